#!/usr/bin/env python3
"""The house rules that a build does not check (docs/architecture.md, "House rules").

usage: house_rules.py ROOT           check the tree at ROOT; exit 1, naming file and line,
                                     when a rule is broken
       house_rules.py --self-test DIR  break each rule once in a scratch tree under DIR and
                                     check that the check fails for it, then that a clean
                                     scratch tree passes

Rules:
  * no C or C++ source in daemon/ or externals/ over 900 lines;
  * no Markdown file in docs/ (nor README.md) over 500 lines;
  * no issue-tracker number (the word followed by a number, with or without "#") in any text file:
    history stays in git, docs and comments say what is;
  * at most 2 edits of Python's module search path in the tree (the helpers are one package,
    imported by name; docs/python.md);
  * tests/ mirrors daemon/src/: a tests/<area>/ for every area, and no other folder in tests/
    but those kept apart (TESTS_APART).
The files are those git tracks when ROOT is a git checkout, else every file below ROOT.
"""

import os
import re
import subprocess
import sys
import tempfile

MAX_SOURCE_LINES = 900
MAX_DOC_LINES = 500
MAX_PATH_EDITS = 2

SOURCE_EXT = (".c", ".h", ".cpp", ".hpp")
TEXT_EXT = SOURCE_EXT + (".py", ".sh", ".md", ".txt", ".cmake", ".pd", ".json", ".in")
# Written in pieces so that this file does not match its own patterns.
ISSUE_RE = re.compile(r"\b" + "iss" + r"ues?\s*#?\s*[0-9]+", re.IGNORECASE)
PATH_EDIT_RE = re.compile(r"\b" + "sys" + r"\.path\s*(\.\s*(insert|append|extend)\s*\(|\[[^\]]*\]\s*=[^=]|\+=|=[^=])")
SYS_PATH = "sys" + ".path"
SKIP_DIRS = {".git", "__pycache__"}
# The folders of tests/ that test no daemon area (docs/architecture.md, "Tests").
TESTS_APART = {"core", "pd", "pdosc", "sound", "ui", "e2e", "layout", "package", "support", "corpus"}


def tree_files(root):
    """Relative paths of the files of the tree: git's list, or a walk."""
    try:
        out = subprocess.run(["git", "-C", root, "ls-files", "-z"], capture_output=True,
                             check=True).stdout.decode()
        files = [f for f in out.split("\0") if f]
        if files:
            return [f for f in files if os.path.isfile(os.path.join(root, f))]
    except (OSError, subprocess.CalledProcessError):
        pass
    files = []
    for d, dirs, names in os.walk(root):
        dirs[:] = [x for x in dirs if x not in SKIP_DIRS and not x.startswith("build")]
        for n in names:
            files.append(os.path.relpath(os.path.join(d, n), root))
    return files


def read_lines(path):
    with open(path, "rb") as f:
        return f.read().decode("utf-8", "replace").splitlines()


def check(root):
    """The broken rules, as 'file:line: message' strings."""
    problems = []
    path_edits = []
    for rel in sorted(tree_files(root)):
        if not rel.endswith(TEXT_EXT) and os.path.basename(rel) not in ("CMakeLists.txt", "README"):
            continue
        lines = read_lines(os.path.join(root, rel))
        top = rel.split("/")[0]
        if top in ("daemon", "externals") and rel.endswith(SOURCE_EXT) and len(lines) > MAX_SOURCE_LINES:
            problems.append(f"{rel}:{len(lines)}: {len(lines)} lines, more than {MAX_SOURCE_LINES}: "
                            "a room with several jobs (split it by job)")
        if (top == "docs" or rel == "README.md") and rel.endswith(".md") and len(lines) > MAX_DOC_LINES:
            problems.append(f"{rel}:{len(lines)}: {len(lines)} lines, more than {MAX_DOC_LINES}: "
                            "a doc says what is true now; history stays in git")
        for i, line in enumerate(lines, 1):
            m = ISSUE_RE.search(line)
            if m:
                problems.append(f"{rel}:{i}: names an issue number ('{m.group(0)}'): say the fact instead")
            if rel.endswith((".py", ".sh")) and PATH_EDIT_RE.search(line):
                path_edits.append(f"{rel}:{i}")
    problems += check_test_folders(tree_files(root))
    if len(path_edits) > MAX_PATH_EDITS:
        problems.append(f"{len(path_edits)} edits of Python's module path, more than {MAX_PATH_EDITS} "
                        f"(import the helpers' package by name): {', '.join(path_edits)}")
    return problems


def check_test_folders(files):
    """tests/<area>/ for every daemon/src/<area>/, and nothing else but TESTS_APART."""
    areas = {f.split("/")[2] for f in files if f.startswith("daemon/src/") and f.count("/") >= 3}
    folders = {f.split("/")[1] for f in files if f.startswith("tests/") and f.count("/") >= 2}
    problems = [f"tests/{a}/: missing: the tests of daemon/src/{a}/ belong there"
                for a in sorted(areas - folders)]
    problems += [f"tests/{t}/: neither a daemon area nor a folder kept apart ({', '.join(sorted(TESTS_APART))})"
                 for t in sorted(folders - areas - TESTS_APART)]
    return problems


def self_test(scratch):
    """Each rule broken once must fail; a clean tree must pass."""
    def tree(files):
        d = tempfile.mkdtemp(dir=scratch)
        for rel, text in files.items():
            p = os.path.join(d, rel)
            os.makedirs(os.path.dirname(p), exist_ok=True)
            with open(p, "w") as f:
                f.write(text)
        return d

    clean = {"daemon/src/a/a.cpp": "int a;\n" * MAX_SOURCE_LINES,
             "tests/a/test_a.cpp": "int t;\n",
             "docs/a.md": "# A\n" + "text\n" * (MAX_DOC_LINES - 1),
             "tests/t.py": f"import sys\n{SYS_PATH}.insert(0, 'x')\n",
             "scripts/s.py": f"import sys\n{SYS_PATH}.append('y')\nprint({SYS_PATH}[0])\n"}
    cases = {
        "long source": ({"externals/core/m.c": "int a;\n" * (MAX_SOURCE_LINES + 1)}, "more than 900"),
        "long doc": ({"docs/b.md": "x\n" * (MAX_DOC_LINES + 1)}, "more than 500"),
        "issue number": ({"daemon/src/a/b.cpp": "// as " + "Issue" + " #12 asked\n"}, "issue number"),
        "issue numbers": ({"docs/c.md": "see " + "issues" + " 3 and 4\n"}, "issue number"),
        "area without tests": ({"daemon/src/b/b.cpp": "int b;\n"}, "tests/b/: missing"),
        "stray test folder": ({"tests/kinematics/t.cpp": "int k;\n"}, "neither a daemon area"),
        "path edits": ({"bench/b.py": f"import sys\n{SYS_PATH}[0:0] = ['z']\n"}, "edits of Python"),
    }
    passed = failures = 0
    found = check(tree(clean))
    if found:
        print("FAILED: a clean tree broke the rules:", *found, sep="\n  ")
        failures += 1
    else:
        print("ok: a clean tree passes")
        passed += 1
    for name, (extra, expect) in cases.items():
        found = check(tree({**clean, **extra}))
        if not any(expect in p for p in found):
            print(f"FAILED: '{name}' was not caught (expected '{expect}', got {found})")
            failures += 1
        else:
            print(f"ok: '{name}' caught")
            passed += 1
    return passed, failures


def main(argv):
    if len(argv) == 3 and argv[1] == "--self-test":
        os.makedirs(argv[2], exist_ok=True)
        passed, failures = self_test(argv[2])
        print(f"{passed} passed, {failures} failed")
        return 1 if failures else 0
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    problems = check(argv[1])
    for p in problems:
        print(p, file=sys.stderr)
    print(f"house rules: {len(problems)} broken" if problems else "house rules: all kept")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
