"""Box extents of a Pd patch file as Pd 0.53 draws them with Debian's default
font, for the overlap test (test_help_layout.py).

The numbers (docs/ui.md, "Layout of the shipped patches"):
- Font metrics: Pd asks its GUI for the largest font of its family that fits
  each nominal size (pd-gui.tcl, fit_font_into_metrics, against
  font_metrics 5x11 6x13 7x16 10x19 14x29 22x44) and sizes every box with what
  the GUI reports. Measured with Debian 12's pd-gui 0.53.1 under Xvfb (a GUI
  plugin printing ::font_measured), DejaVu Sans Mono bold, Pd's Linux default:
  size 8 -> 5x10 px, 10 -> 6x13, 12 -> 7x15, 16 -> 10x19, 24 -> 14x29,
  36 -> 22x44 (character width x line height).
- Box geometry (g_rtext.c, rtext_formattext): the text as Pd prints it
  (binbuf_gettext: atoms joined by one space, none before ',' or ';', a
  newline after ';', numbers in %g), broken into lines at the last space
  before the width limit (the box's ', f N', else 60 characters); width =
  columns * char width + 2 + 2, height = lines * line height + 3 + 2.
  Object and message boxes are at least 3 columns wide.
- Atom boxes (floatatom/symbolatom/listbox): their width in characters
  (0: 5 for a number, 10 for a symbol or list) plus the same margins, one line.
- IEM GUIs by their size arguments: bng/tgl SIZE, nbx (g_numbox.c) DIGITS *
  its font size * 31/36 + height/2 + 4,
  hsl/vsl W H, hradio/vradio SIZE*N, vu W H, and their labels (anchored west at
  their offsets, in their font size); cnv is a background, never checked.
- Graph-on-parent subpatches and arrays by their #X coords size.
"""
import os
import re

# Pd font size -> (char width, line height) in pixels, measured as above.
FONT_METRICS = {8: (5, 10), 10: (6, 13), 12: (7, 15), 16: (10, 19), 24: (14, 29), 36: (22, 44)}
LMARGIN, RMARGIN, TMARGIN, BMARGIN = 2, 2, 3, 2
DEFAULT_BOX_WIDTH = 60
_SIZES = (8, 10, 12, 16, 24, 36)


def font_metrics(size):
    """Pd's nearest font (sys_findfont): the largest nominal size <= size."""
    chosen = _SIZES[0]
    for s in _SIZES:
        if size >= s:
            chosen = s
    return FONT_METRICS[chosen]


def split_records(text, with_offsets=False):
    """The file's records: 'a b c;' each, ';' escaped as '\\;' kept inside
    (with_offsets: (record, offset of its first character in text))."""
    records, start, i = [], 0, 0
    while i < len(text):
        c = text[i]
        if c == "\\" and i + 1 < len(text):
            i += 2
            continue
        if c == ";":
            raw = text[start:i]
            lead = len(raw) - len(raw.lstrip())
            if raw.strip():
                records.append((raw.strip(), start + lead))
            start = i + 1
        i += 1
    return records if with_offsets else [r for r, _ in records]


def atoms(record):
    """Pd's atoms of a record: ('sym'|'float'|'comma'|'semi', text)."""
    out = []
    # binbuf_text: whitespace separates atoms; an unescaped ',' or ';' is an
    # atom of its own even when glued to a word ("shown, f 30").
    for tok in re.findall(r"[,;]|(?:\\.|[^\s\\,;])+", record):
        if tok == ",":
            out.append(("comma", ","))
        elif tok == "\\,":
            out.append(("comma", ","))
        elif tok == "\\;":
            out.append(("semi", ";"))
        else:
            try:
                value = float(tok)
                if re.fullmatch(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?", tok):
                    out.append(("float", "%g" % value))
                    continue
            except ValueError:
                pass
            out.append(("sym", re.sub(r"\\(.)", r"\1", tok)))
    return out


def box_text(items):
    """binbuf_gettext: what the box shows."""
    buf = ""
    for kind, text in items:
        if kind in ("comma", "semi") and buf.endswith(" "):
            buf = buf[:-1]
        buf += text + ("\n" if kind == "semi" else " ")
    return buf[:-1] if buf else ""


def wrap(text, limit):
    """rtext_formattext's line breaking -> (lines, columns)."""
    lines, columns, i, n = 0, 0, 0, len(text)
    while n - i > 0:
        rest = text[i:]
        max_c = min(len(rest), limit)
        nl = rest.find("\n", 0, max_c)
        eat = 1
        if nl < 0:
            if len(rest) > limit:
                sp = rest.rfind(" ", 0, max_c + 1)
                if sp < 0:
                    found, eat = max_c, 0
                else:
                    found = sp
            else:
                found, eat = len(rest), 0
        else:
            found = nl
        columns = max(columns, found)
        lines += 1
        i += found + eat
    return max(lines, 1), columns


def split_width(items):
    """A trailing ', f N' is the box width, not text."""
    if (len(items) >= 3 and items[-3][0] == "comma" and items[-2] == ("sym", "f")
            and items[-1][0] == "float"):
        return items[:-3], int(float(items[-1][1]))
    return items, 0


def text_extent(items, kind, cw, lh):
    """(w, h) of an object, message or comment box: Pd's rectangle."""
    return _text_layout(items, kind, cw, lh)[:2]


def _text_layout(items, kind, cw, lh):
    items, width_c = split_width(items)
    text = box_text(items)
    lines, columns = wrap(text, width_c or DEFAULT_BOX_WIDTH)
    text_columns = columns
    if width_c:
        columns = width_c
    elif kind in ("obj", "msg"):
        columns = max(columns, 3)
    elif kind == "text":
        columns = max(columns, 1)
    return (columns * cw + LMARGIN + RMARGIN, lines * lh + TMARGIN + BMARGIN,
            text_columns * cw, lines * lh)


def _num(items, i, default=0.0):
    try:
        return float(items[i][1])
    except (IndexError, ValueError):
        return default


def iemgui_extent(cls, args, cw, lh):
    """(w, h) of an IEM GUI from its creation arguments, None for cnv/unknown."""
    if cls in ("bng", "tgl"):
        s = _num(args, 0, 15)
        return s, s
    if cls in ("hsl", "vsl"):
        return _num(args, 0, 128 if cls == "hsl" else 15), _num(args, 1, 15 if cls == "hsl" else 128)
    if cls in ("hradio", "hdl", "vradio", "vdl"):
        s, n = _num(args, 0, 15), _num(args, 3, 8)
        return (s * n, s) if cls in ("hradio", "hdl") else (s, s * n)
    if cls == "nbx":
        # g_numbox.c, my_numbox_calc_fontwidth: its own font size and style
        digits, h = _num(args, 0, 5), _num(args, 1, 14)
        style, size = int(_num(args, 11, 0)), int(_num(args, 12, 10))
        per_char = {1: 27, 2: 25}.get(style, 31)
        return int(size * per_char * digits) // 36 + int(h) // 2 + 4, h
    if cls == "vu":
        return _num(args, 0, 15), _num(args, 1, 120)
    return None


# Where an IEM GUI's label, its x y offsets and font size are among its
# creation arguments (after the class name).
LABEL_ARGS = {"bng": 6, "tgl": 4, "hsl": 8, "vsl": 8, "nbx": 8, "hradio": 6, "vradio": 6,
              "hdl": 6, "vdl": 6, "vu": 3}


def iemgui_label(cls, args, x, y):
    """(text, x, y, w, h) of an IEM GUI's label (anchored west, centred on
    y + its y offset, in its own font size), or None."""
    i = LABEL_ARGS.get(cls)
    if i is None or len(args) < i + 5 or args[i][1] in ("empty", "-"):
        return None
    text = args[i][1].replace("_", " ")
    cw, lh = font_metrics(int(_num(args, i + 4, 10)))
    lx, ly = x + _num(args, i + 1), y + _num(args, i + 2)
    return text, lx, ly - lh // 2, len(text) * cw, lh


class Box:
    """A box's rectangle as Pd computes it (x, y, w, h) and what is seen of it
    (visible: the same for boxes with a border; for a comment, which has none,
    only its glyphs: the lines' longest text inside the margins)."""

    def __init__(self, canvas, index, kind, x, y, w, h, text, visible=None, offset=None):
        self.canvas, self.index, self.kind, self.offset = canvas, index, kind, offset
        self.x, self.y, self.w, self.h, self.text = x, y, w, h, text
        self.visible = visible or (x, y, w, h)
        self.owner = None  # for a label: its IEM GUI

    def overlaps(self, other):
        if self.owner is other or other.owner is self:
            return False  # an IEM GUI and its own label
        ax, ay, aw, ah = self.visible
        bx, by, bw, bh = other.visible
        return ax < bx + bw and bx < ax + aw and ay < by + bh and by < ay + ah

    def __repr__(self):
        return "%s #%d at (%d,%d) %dx%d '%s'" % (self.kind, self.index, self.x, self.y, self.w,
                                                 self.h, self.text[:50])


def gop_size(path):
    """(w, h) of a graph-on-parent abstraction (its top canvas's #X coords), else None."""
    depth = 0
    for rec in split_records(open(path, encoding="utf-8").read()):
        items = atoms(rec)
        if len(items) < 2:
            continue
        if items[0][1] == "#N" and items[1][1] == "canvas":
            depth += 1
        elif items[0][1] == "#X" and items[1][1] == "restore":
            depth -= 1
        elif depth == 1 and items[0][1] == "#X" and items[1][1] == "coords":
            if len(items) >= 9 and _num(items, 8) >= 1:
                return _num(items, 6), _num(items, 7)
    return None


def parse(path, abstraction_dirs=(), gop_areas=None, wiring=None):
    """{canvas name: [Box]} for every canvas of the file (the top one is '').
    An object whose class is an abstraction found in `abstraction_dirs` and
    drawn graph-on-parent takes that abstraction's size. gop_areas (a dict),
    if given, receives each graph-on-parent canvas's area (x, y, w, h): what
    the parent shows of it. wiring (a dict), if given, receives each canvas's
    (window (w, h), [(source, outlet, sink, inlet)], {index: (inlets, outlets)})
    for its objects known to have inlets and outlets (abstractions, subpatches)."""
    records = split_records(open(path, encoding="utf-8").read(), with_offsets=True)
    canvases = {}
    stack = []  # [name, font, boxes, index, coords]
    font = 12
    for rec, offset in records:
        items = atoms(rec)
        if len(items) < 2:
            continue
        head, kind = items[0][1], items[1][1]
        if head == "#N" and kind == "canvas":
            if not stack:
                font = int(_num(items, 6, 12))
                name = ""
            else:
                name = stack[-1][0] + "/" + (items[6][1] if len(items) > 6 else "?")
            stack.append([name, font, [], 0, None])
            if wiring is not None:
                wiring[name] = ((_num(items, 4), _num(items, 5)), [], {})
            continue
        if head != "#X" or not stack:
            continue
        top = stack[-1]
        if kind == "connect" and wiring is not None and len(items) >= 6:
            wiring[top[0]][1].append(tuple(int(_num(items, i)) for i in range(2, 6)))
            continue
        cw, lh = font_metrics(top[1])
        if kind == "coords":
            # #X coords x1 y1 x2 y2 w h gop [xmargin ymargin]
            if len(items) >= 9 and _num(items, 8) >= 1:
                top[4] = (_num(items, 6), _num(items, 7))
                if gop_areas is not None:
                    gop_areas[top[0]] = (_num(items, 9), _num(items, 10), top[4][0], top[4][1])
            continue
        if kind == "restore":
            name, _, boxes, _, gop = stack.pop()
            canvases[name] = boxes
            if not stack:
                continue
            parent = stack[-1]
            pcw, plh = font_metrics(parent[1])
            x, y = _num(items, 2), _num(items, 3)
            rest = items[4:]
            if gop is not None:
                w, h = gop
            else:
                w, h = text_extent(rest, "obj", pcw, plh)
            parent[2].append(Box(parent[0], parent[3], "obj", x, y, w, h, box_text(rest),
                                 offset=offset))
            if wiring is not None:
                wiring[parent[0]][2][parent[3]] = iolets([b.text for b in boxes])
            parent[3] += 1
            continue
        if kind in ("obj", "msg", "text", "floatatom", "symbolatom", "listbox"):
            x, y = _num(items, 2), _num(items, 3)
            rest = items[4:]
            if kind == "obj":
                cls = rest[0][1] if rest else ""
                if cls == "cnv":
                    top[3] += 1  # a background: drawn under the boxes on purpose
                    continue
                ext = iemgui_extent(cls, rest[1:], cw, lh)
                for d in abstraction_dirs:
                    if os.path.isfile(os.path.join(d, cls + ".pd")):
                        if not ext:
                            ext = gop_size(os.path.join(d, cls + ".pd"))
                        if wiring is not None:
                            wiring[top[0]][2][top[3]] = abstraction_iolets(
                                os.path.join(d, cls + ".pd"))
                        break
                w, h = ext if ext else text_extent(rest, "obj", cw, lh)
            elif kind == "msg":
                w, h = text_extent(rest, kind, cw, lh)
                w += h // 4  # the flag on its right side (g_text.c: corner = height / 4)
            elif kind == "text":
                w, h, tw, th = _text_layout(rest, kind, cw, lh)
                top[2].append(Box(top[0], top[3], kind, x, y, w, h, box_text(rest),
                                  (x + LMARGIN, y + TMARGIN, tw, th), offset))
                top[3] += 1
                continue
            else:
                width_c = int(_num(items, 4, 0)) or (5 if kind == "floatatom" else 10)
                w, h = width_c * cw + LMARGIN + RMARGIN, lh + TMARGIN + BMARGIN
            box = Box(top[0], top[3], kind, x, y, w, h, box_text(rest), offset=offset)
            top[2].append(box)
            label = iemgui_label(rest[0][1], rest[1:], x, y) if kind == "obj" and rest else None
            if label:
                text, lx, ly, lw, lhh = label
                lab = Box(top[0], top[3], "label", lx, ly, lw, lhh, text)
                lab.owner = box
                top[2].append(lab)
            top[3] += 1
    while stack:  # the top canvas has no #X restore
        name, _, boxes, _, _ = stack.pop()
        canvases[name] = boxes
    return canvases


def overlaps(path, abstraction_dirs=()):
    """Every pair of boxes of one canvas whose extents intersect."""
    found = []
    for name, boxes in parse(path, abstraction_dirs).items():
        for i, a in enumerate(boxes):
            for b in boxes[i + 1:]:
                if a.overlaps(b):
                    found.append((name, a, b))
    return found


# Cables and windows (g_canvas.h, g_text.c: an inlet or outlet is IOWIDTH = 7 px
# wide, the first at the box's left edge, the last at its right, the others
# spread evenly; a cable runs from the middle of its outlet on the box's bottom
# edge to the middle of its inlet on the top edge).
IOWIDTH = 7
IOMIDDLE = (IOWIDTH - 1) // 2


def iolets(texts):
    """(inlets, outlets) of a canvas whose objects' texts are given."""
    ins = sum(1 for t in texts if t.split()[:1] in (["inlet"], ["inlet~"]))
    outs = sum(1 for t in texts if t.split()[:1] in (["outlet"], ["outlet~"]))
    return ins, outs


def abstraction_iolets(path):
    """(inlets, outlets) of an abstraction file's top canvas."""
    depth, texts = 0, []
    for rec in split_records(open(path, encoding="utf-8").read()):
        items = atoms(rec)
        if len(items) < 5:
            if len(items) >= 2 and items[1][1] == "restore":
                depth -= 1
            continue
        if items[0][1] == "#N" and items[1][1] == "canvas":
            depth += 1
        elif items[1][1] == "restore":
            depth -= 1
        elif depth == 1 and items[1][1] == "obj":
            texts.append(items[4][1])
    return iolets(texts)


def _iolet_x(box, n, count):
    """x of the middle of iolet n of `count` on the box."""
    if count <= 1:
        return box.x + IOMIDDLE
    return box.x + (box.w - IOWIDTH) * n // (count - 1) + IOMIDDLE


def segment_hits(x1, y1, x2, y2, rect):
    """Whether the segment (x1,y1)-(x2,y2) meets the closed rectangle (x, y, w, h)
    (Liang-Barsky clipping)."""
    rx, ry, rw, rh = rect
    t0, t1 = 0.0, 1.0
    dx, dy = x2 - x1, y2 - y1
    for p, q in ((-dx, x1 - rx), (dx, rx + rw - x1), (-dy, y1 - ry), (dy, ry + rh - y1)):
        if p == 0:
            if q < 0:
                return False
            continue
        t = q / p
        if p < 0:
            t0 = max(t0, t)
        else:
            t1 = min(t1, t)
        if t0 > t1:
            return False
    return True


def cables(path, abstraction_dirs=()):
    """Every cable of every canvas as (canvas, source box, sink box, (x1, y1, x2, y2)).
    Iolet counts: an abstraction's or subpatch's inlets and outlets; for other
    objects at least the highest iolet any cable uses (a cable from the last
    outlet of a class with more outlets than used is placed at the box's right
    edge, a few pixels off)."""
    wiring = {}
    canvases = parse(path, abstraction_dirs, wiring=wiring)
    found = []
    for name, boxes in canvases.items():
        _, edges, known = wiring.get(name, ((0, 0), [], {}))
        by_index = {b.index: b for b in boxes if b.kind != "label"}
        used_out, used_in = {}, {}
        for s, o, d, i in edges:
            used_out[s] = max(used_out.get(s, 0), o + 1)
            used_in[d] = max(used_in.get(d, 0), i + 1)
        for s, o, d, i in edges:
            a, b = by_index.get(s), by_index.get(d)
            if a is None or b is None:
                continue
            nout = known[s][1] if s in known else used_out[s]
            nin = known[d][0] if d in known else used_in[d]
            found.append((name, a, b, (_iolet_x(a, o, nout), a.y + a.h,
                                       _iolet_x(b, i, nin), b.y)))
    return canvases, found


def crossings(path, abstraction_dirs=()):
    """Every cable that meets a box, GUI or label other than its own two boxes
    (what is seen of it: a comment's glyphs), as (canvas, box, cable's source,
    sink)."""
    canvases, wires = cables(path, abstraction_dirs)
    found = []
    for name, a, b, seg in wires:
        for box in canvases[name]:
            if box is a or box is b or box.owner is a or box.owner is b:
                continue
            if segment_hits(*seg, box.visible):
                found.append((name, box, a, b))
    return found


def outside_window(path, abstraction_dirs=()):
    """Every box, GUI or label past the right or bottom edge of its canvas's
    window (#N canvas X Y W H), as (canvas, box, (W, H)). Graph-on-parent
    canvases are shown in their parent and not checked."""
    wiring, gops = {}, {}
    canvases = parse(path, abstraction_dirs, gop_areas=gops, wiring=wiring)
    found = []
    for name, boxes in canvases.items():
        if name in gops:
            continue
        (w, h), _, _ = wiring[name]
        for box in boxes:
            x, y, bw, bh = box.visible
            if x + bw > w or y + bh > h:
                found.append((name, box, (w, h)))
    return found
