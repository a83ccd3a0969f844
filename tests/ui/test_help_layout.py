"""No two boxes overlap in any shipped patch (help/, patches/), with box
extents as Pd 0.53 draws them in Debian's default font (ictus_tools.pdlayout: DejaVu
Sans Mono bold, 7 x 15 px per character at Pd's size 12, measured in the real
GUI; docs/ui.md). The model itself is checked first against extents measured
in the real pd-gui under Xvfb, and on a patch with a known overlap. Every help
patch also has its "see also" as object boxes (right-click > Help), and every
help patch that makes sound (has a [dac~]) a volume slider that reaches it.
In the help patches and the main patch no cable meets a box or GUI other than
its own two, and nothing lies past its window's edge."""
import argparse
import glob
import os
import tempfile

from ictus_tools import ROOT as REPO
from ictus_tools import checks, pdlayout
from ictus_tools.checks import check

ABSTRACTIONS = [os.path.join(REPO, d) for d in ("patches", "patches/ui", "patches/sound")]
ap = argparse.ArgumentParser()
ap.add_argument("--build")  # unused: the patches are read from the sources
ap.parse_args()
checks.keep_going()  # every patch is reported before the test ends


def patch(text):
    f = tempfile.NamedTemporaryFile("w", suffix=".pd", delete=False)
    f.write(text)
    f.close()
    return f.name


# 1. The model against the real GUI: rectangles of contact~-help.pd's boxes as
# Tk reported them (pd-gui 0.53.1, Xvfb, Debian 12; canvas bbox minus Tk's
# 2-px slack), and a comment's glyphs.
known = patch("#N canvas 0 0 600 400 12;\n"
              "#X obj 20 14 contact~ help-contact-drum;\n"     # 186 x 20
              "#X msg 20 60 hit 1 0.3 0;\n"                    # 86 x 20 (flag included)
              "#X msg 480 60 \\; pd dsp 1;\n"                  # 68 x 35: two lines
              "#X obj 300 250 dac~;\n"                         # 32 x 20
              "#X text 230 14 - a stick hitting a membrane~ (nonlinear contact);\n"  # 343 x 15 glyphs
              "#X text 660 180 <- replies are shown, f 30;\n"  # box 30 columns, glyphs 20
              "#X text 20 500 " + " ".join(["word"] * 30) + ";\n")  # 149 chars: 3 lines of <= 60
boxes = pdlayout.parse(known)[""]
check([(b.w, b.h) for b in boxes[:4]] == [(186, 20), (86, 20), (68, 35), (32, 20)],
      "object and message boxes measure as in pd-gui: %s" % [(b.w, b.h) for b in boxes[:4]])
check(boxes[4].visible[2:] == (343, 15),
      "a comment's glyphs measure as in pd-gui: %s" % (boxes[4].visible[2:],))
check(boxes[5].w == 30 * 7 + 4 and boxes[5].visible[2] == 20 * 7,
      "', f 30' sets a comment's box, not its glyphs: %d, %d" % (boxes[5].w, boxes[5].visible[2]))
check(boxes[6].h == 3 * 15 + 5 and boxes[6].visible[2] == 59 * 7,
      "a long comment wraps at 60 characters on a space: %d lines, %d px"
      % ((boxes[6].h - 5) // 15, boxes[6].visible[2]))
os.remove(known)

# 2. The check finds an overlap: two comments 15 px apart whose first wraps.
bad = patch("#N canvas 0 0 600 400 12;\n#X text 20 20 " + " ".join(["word"] * 20) + ";\n"
            "#X text 20 35 next;\n#X obj 100 200 f;\n#X obj 110 205 f;\n")
found = pdlayout.overlaps(bad)
check(len(found) == 2,
      "the check finds a wrapped comment over the next and two stacked boxes: %d" % len(found))
os.remove(bad)

# 3. Every shipped patch.
patches = sorted(glob.glob(os.path.join(REPO, "help", "*.pd")) +
                 glob.glob(os.path.join(REPO, "patches", "**", "*.pd"), recursive=True))
check(len(patches) >= 25, "%d patches to check" % len(patches))
for path in patches:
    name = os.path.relpath(path, REPO)
    found = pdlayout.overlaps(path, ABSTRACTIONS)
    check(not found, "%s: no overlapping boxes%s" % (
           name, "".join("\n    in canvas '%s': %r / %r" % (c, a, b) for c, a, b in found)))

# 4. Cables and windows, in the patches a user reads (every help patch and the
# main patch): no cable meets a box, GUI or label other than its own two (a
# cable is the segment between the middles of its outlet and inlet, Pd's
# g_canvas.h geometry; a comment by its glyphs), nothing past the right or
# bottom edge of its window (#N canvas's size; subpatch windows too). The model
# is first shown to find each kind of defect on a scratch patch.
scratch = patch("#N canvas 0 0 400 300 12;\n"
                "#X msg 20 20 bang;\n#X msg 120 20 stop;\n#X obj 20 120 print fan;\n"
                "#X obj 60 70 hsl 128 15 0 1 0 0 empty empty empty 0 -8 0 10 #fcfcfc #000000 "
                "#000000 0 1;\n"
                "#X text 300 200 cut at the edge;\n"
                "#X connect 0 0 2 0;\n#X connect 1 0 2 0;\n")
crossed = pdlayout.crossings(scratch)
check([(c[1].index, c[2].index) for c in crossed] == [(3, 1)],
      "a slider on a fan of cables is found, and only the cable it sits on: %r" % crossed)
outside = pdlayout.outside_window(scratch)
check([o[1].index for o in outside] == [4], "a comment past the window's edge is found: %r" % outside)
os.remove(scratch)
check(pdlayout.segment_hits(0, 0, 10, 10, (4, 5, 2, 2)) and
      not pdlayout.segment_hits(0, 0, 10, 10, (6, 0, 3, 3)) and
      pdlayout.segment_hits(0, 10, 20, 10, (5, 10, 4, 4)),
      "a segment meets a rectangle it crosses or runs along, not one beside it")
read = sorted(glob.glob(os.path.join(REPO, "help", "*.pd"))) + [
    os.path.join(REPO, "patches", "ictus.pd")]
for path in read:
    name = os.path.relpath(path, REPO)
    crossed = pdlayout.crossings(path, ABSTRACTIONS)
    outside = pdlayout.outside_window(path, ABSTRACTIONS)
    report = "".join("\n    in canvas '%s': cable %r -> %r meets %r" % (c, a, b, box)
                     for c, box, a, b in crossed)
    report += "".join("\n    in canvas '%s': past the window %dx%d: %r" % (c, w, h, box)
                      for c, box, (w, h) in outside)
    # a cable joins two objects: a comment has no inlet or outlet (Pd refuses
    # such a connection at load, "connection failed")
    _, wires = pdlayout.cables(path, ABSTRACTIONS)
    to_comment = [(c, a, b) for c, a, b, _ in wires if "text" in (a.kind, b.kind)]
    check(not to_comment, "%s: no connection from or to a comment%s" % (name, "".join(
        "\n    in canvas '%s': %r -> %r" % w for w in to_comment)))
    check(not crossed and not outside,
          "%s: no cable over a box, nothing past the window's edge%s" % (name, report))

# 5. Help patches: "see also" as object boxes; a volume slider before [dac~].
LIBRARY = {"membrane~", "contact~", "ictus_timetag", "ictus-receive", "ictus-drum", "ictus-sound",
           "ictus-sound-clips", "ictus-sound-synth", "ictus-sound-modal", "ictus-physics",
           "ictus-graphics", "ictus-sound-panel", "ictus-view", "ictus-midi", "ictus-status",
           "ictus-midifile"}
for path in sorted(glob.glob(os.path.join(REPO, "help", "*-help.pd"))):
    name = os.path.basename(path)
    subject = name[:-len("-help.pd")]
    canvases = pdlayout.parse(path, ABSTRACTIONS)
    see_also = []
    for boxes in canvases.values():
        for s in [b for b in boxes if b.kind == "text" and b.text.lower().startswith("see also")]:
            # object boxes on the rows just under the comment
            see_also += [b.text.split()[0] for b in boxes if b.kind == "obj"
                         and s.y < b.y <= s.y + s.h + 30 and b.x >= s.x - 10]
    linked = [o for o in see_also if o in LIBRARY and o != subject]
    check(len(linked) >= 1, "%s: 'see also' names other objects as object boxes: %s" % (name, see_also))

    text = open(path).read()
    records = [pdlayout.atoms(r) for r in pdlayout.split_records(text)]
    if not any(len(a) > 4 and a[1][1] == "obj" and a[4][1] == "dac~" for a in records):
        continue
    # the top canvas's boxes and connections
    depth, index, boxes, edges = 0, 0, {}, []
    for a in records:
        if a[0][1] == "#N" and a[1][1] == "canvas":
            depth += 1
        elif a[1][1] == "restore":
            depth -= 1
            if depth == 1:
                boxes[index] = "pd"
                index += 1
        elif depth == 1 and a[1][1] in ("obj", "msg", "text", "floatatom", "symbolatom", "listbox"):
            boxes[index] = a[4][1] if a[1][1] == "obj" and len(a) > 4 else a[1][1]
            index += 1
        elif depth == 1 and a[1][1] == "connect":
            edges.append((int(float(a[2][1])), int(float(a[4][1]))))
    sliders = [i for i, c in boxes.items() if c in ("hsl", "vsl", "hslider", "vslider")]
    dacs = {i for i, c in boxes.items() if c == "dac~"}

    def reaches(start, goal, through):
        """A path from start to goal passing a box of class `through`."""
        seen, todo = set(), [(start, False)]
        while todo:
            node, passed = todo.pop()
            passed = passed or boxes.get(node) == through
            if node in goal and passed:
                return True
            for a, b in edges:
                if a == node and (b, passed) not in seen:
                    seen.add((b, passed))
                    todo.append((b, passed))
        return False

    check(any(reaches(s, dacs, "*~") for s in sliders),
          "%s: a volume slider reaches [dac~] through a [*~]" % name)

checks.finish()
print("ok: all")
