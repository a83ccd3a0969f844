"""Converts the references in docs/ to HTML for the Pd library folder (docs/ beside
the help patches, cmake/pd_library.cmake), with Debian's python3-markdown.
Links between the references point at the HTML pages; each page names its
Markdown source. Usage: python3 scripts/doc_html.py OUT_DIR FILE.md..."""
import os
import re
import sys

import markdown

PAGE = """<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>ictus: {title}</title>
<style>
body {{ font-family: sans-serif; max-width: 60em; margin: 1em auto; padding: 0 1em;
        line-height: 1.45; }}
pre, code {{ font-family: monospace; background: #f4f4f4; }}
pre {{ padding: 0.5em; overflow-x: auto; }}
table {{ border-collapse: collapse; }}
th, td {{ border: 1px solid #bbb; padding: 0.2em 0.5em; vertical-align: top; }}
img {{ max-width: 100%; }}
</style>
</head>
<body>
<p><small>ictus reference, from {source} (the Markdown beside this page).</small></p>
{body}
</body>
</html>
"""

# A link to another reference (name.md or name.md#anchor), not to a web address.
MD_LINK = re.compile(r'href="(?![a-z]+://)([^"#]+)\.md(#[^"]*)?"')


def convert(source, out_dir):
    text = open(source, encoding="utf-8").read()
    title = next((line.lstrip("# ").strip() for line in text.splitlines()
                  if line.startswith("#")), os.path.basename(source))
    body = markdown.markdown(text, extensions=["tables", "fenced_code", "toc"],
                             extension_configs={"toc": {"slugify": github_slug}})
    body = MD_LINK.sub(lambda m: 'href="%s.html%s"' % (m.group(1), m.group(2) or ""), body)
    name = os.path.splitext(os.path.basename(source))[0]
    page = PAGE.format(title=escape(title), source=name + ".md", body=body)
    with open(os.path.join(out_dir, name + ".html"), "w", encoding="utf-8") as f:
        f.write(page)


def github_slug(value, separator):
    """Heading anchors as GitHub makes them, which the references link to:
    lower case, punctuation dropped, each space a '-'."""
    value = re.sub(r"[^\w\- ]", "", value.strip().lower())
    return value.replace(" ", separator)


def escape(s):
    return s.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def main():
    if len(sys.argv) < 3:
        sys.exit("usage: doc_html.py OUT_DIR FILE.md...")
    out_dir = sys.argv[1]
    os.makedirs(out_dir, exist_ok=True)
    for source in sys.argv[2:]:
        convert(source, out_dir)


if __name__ == "__main__":
    main()
