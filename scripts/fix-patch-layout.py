#!/usr/bin/env python3
"""Moves the boxes of Pd patches apart until none overlaps another, with box
extents as Pd 0.53 draws them in Debian's default font (ictus_tools.pdlayout,
the same model tests/ui/test_help_layout.py checks with).

    python3 scripts/fix-patch-layout.py FILE.pd ...

Per canvas, boxes are taken top to bottom, left to right. A box that overlaps
one already placed is moved: down (with every box at or below it, so that the
space is inserted and the layout below keeps its shape) when it starts below
the other's top, else right (with the boxes of its row to its right). Only the
x y of boxes change; connections are by index and stay. A tool, run by hand:
look at the result in Pd before committing it."""
import os
import re
import sys

# Run by hand: the one bootstrap that finds the helpers' package (python/ in this repository).
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
from ictus_tools import ROOT, pdlayout  # noqa: E402

GAP = 4
ABSTRACTIONS = [os.path.join(ROOT, d) for d in ("patches", "patches/ui", "patches/sound")]


def shift(box, dx, dy):
    box.x += dx
    box.y += dy
    vx, vy, vw, vh = box.visible
    box.visible = (vx + dx, vy + dy, vw, vh)


def relayout(boxes, gop_area=None):
    """Moves boxes apart; those inside a graph-on-parent area stay (they are
    what the parent shows: an overlap there is fixed by hand)."""
    def frozen(b):
        if b.kind == "label":  # an IEM GUI's label: it follows its GUI, not moved alone
            return True
        if not gop_area:
            return False
        gx, gy, gw, gh = gop_area
        return gx <= b.x < gx + gw and gy <= b.y < gy + gh

    placed = [b for b in boxes if frozen(b)]
    order = sorted((b for b in boxes if not frozen(b)), key=lambda b: (b.y, b.x))
    for i, b in enumerate(order):
        for _ in range(1000):
            hit = next((p for p in placed if b.overlaps(p)), None)
            if hit is None:
                break
            bx, by, bw, bh = b.visible
            px, py, pw, ph = hit.visible
            rest = order[i:]
            if by > py or frozen(hit):
                dy = max(py + ph + GAP - by, 1)
                top = b.y
                for r in rest:
                    if r.y >= top:
                        shift(r, 0, dy)
            else:
                dx = px + pw + GAP * 2 - bx
                left, row = b.x, b.y
                for r in rest:
                    if abs(r.y - row) < 10 and r.x >= left:
                        shift(r, dx, 0)
        placed.append(b)


def fix(path):
    text = open(path, encoding="utf-8").read()
    moves = {}
    gops = {}
    for name, boxes in pdlayout.parse(path, ABSTRACTIONS, gops).items():
        before = {id(b): (b.x, b.y) for b in boxes}
        relayout(boxes, gops.get(name))
        for b in boxes:
            if b.offset is not None and (b.x, b.y) != before[id(b)]:
                moves[b.offset] = (b.x, b.y)
    for offset in sorted(moves, reverse=True):
        m = re.compile(r"#X\s+\w+\s+(-?[\d.]+)\s+(-?[\d.]+)").match(text, offset)
        x, y = moves[offset]
        text = text[:m.start(1)] + "%d %d" % (x, y) + text[m.end(2):]
    if moves:
        open(path, "w", encoding="utf-8").write(text)
    return len(moves)


if __name__ == "__main__":
    for f in sys.argv[1:]:
        moved = fix(f)
        left = len(pdlayout.overlaps(f, ABSTRACTIONS))
        print("%s: %d boxes moved, %d overlaps left" % (f, moved, left))
