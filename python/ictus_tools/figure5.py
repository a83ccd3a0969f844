"""The paper's Figure 5 from a render folder: the heights of the right and left
stick tips against time, the score above them, the strike list marked.

  usage: python3 -m ictus_tools.figure5 DIR [--out STEM] [--title TEXT]

(run by scripts/main.sh and scripts/figure5.sh, which put python/ on PYTHONPATH)

Reads what `ictusd render --score FILE --out DIR` writes (docs/osc.md,
docs/main-job.md):
  DIR/tips.csv     time_s, then per hand the target and simulated tip
                   position (m, world, y up); the height is the y column
  DIR/notes.csv    one line per note: its time (s), hand, nuance, tempo (bpm)
  DIR/strikes.csv  the strike log (bounces have bounce = 1)
  DIR/render.json  the drum (its centre height is drawn as a line), optional
Writes STEM.png and STEM.svg (default DIR/tips) and prints a short summary:
notes, primary strikes, bounces, and each note's primary strike against the
note's time (the timing error). Column names are matched by their words
(left/l/0, right/r/1; target/ref; sim/actual; y), and the columns found are
printed, so a renamed column is an error that names what is there."""
import argparse
import csv
import json
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

HANDS = ("right", "left")  # plotting order; strikes.csv: 0 left, 1 right
HAND_ID = {"left": 0, "right": 1}
COLOURS = {"right": "tab:red", "left": "tab:blue"}
SHORT = {"legato": "leg", "tenuto": "ten", "accent": "acc", "vertical_accent": "v.acc",
         "staccato": "stac"}


def die(message):
    sys.exit("figure5: " + message)


def read_table(path):
    if not os.path.isfile(path):
        die("%s is missing" % path)
    with open(path, newline="") as f:
        rows = [r for r in csv.reader(line for line in f if not line.startswith("#"))]
    if not rows:
        die("%s is empty" % path)
    header = [h.strip() for h in rows[0]]
    return header, [r for r in rows[1:] if r]


def words(name):
    return set(w for w in re.split(r"[^a-z0-9]+", name.lower()) if w)


def hand_of(name):
    w = words(name)
    if w & {"left", "l", "lh"} or name.lower().startswith(("left", "l_")):
        return "left"
    if w & {"right", "r", "rh"} or name.lower().startswith(("right", "r_")):
        return "right"
    return None


def tip_columns(header):
    """{(hand, kind): index of the height column}, kind 'sim' or 'target'."""
    found = {}
    for i, name in enumerate(header):
        w = words(name)
        if not (w & {"y", "y_m", "height"} or re.search(r"(^|_)y(_m)?$", name.lower())):
            continue
        hand = hand_of(name)
        if hand is None:
            continue
        kind = "target" if w & {"target", "ref", "reference", "desired"} else "sim"
        found.setdefault((hand, kind), i)
    return found


def column(header, rows, names, path, convert=float, required=True):
    for name in names:
        if name in header:
            i = header.index(name)
            return [convert(r[i]) for r in rows]
    if required:
        die("%s: no column %s (columns: %s)" % (path, " or ".join(names), ", ".join(header)))
    return None


def hand_value(text):
    t = str(text).strip().lower()
    if t in ("0", "l", "left"):
        return "left"
    if t in ("1", "r", "right"):
        return "right"
    die("hand '%s' is neither left nor right" % text)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("dir")
    ap.add_argument("--out", help="output stem (default DIR/tips)")
    ap.add_argument("--title", default="Stick-tip heights (paper, Figure 5)")
    args = ap.parse_args()
    d = args.dir
    stem = args.out or os.path.join(d, "tips")

    tips_path = os.path.join(d, "tips.csv")
    header, rows = read_table(tips_path)
    t = np.array(column(header, rows, ["time_s", "time"], tips_path))
    cols = tip_columns(header)
    for hand in HANDS:
        if (hand, "sim") not in cols:
            die("%s: no simulated height (y) column for the %s hand (columns: %s)"
                 % (tips_path, hand, ", ".join(header)))
    print("figure5: %s columns used: %s" % (tips_path, ", ".join(
        "%s %s = %s" % (h, k, header[i]) for (h, k), i in sorted(cols.items()))))
    height = {key: np.array([float(r[i]) for r in rows]) for key, i in cols.items()}

    notes_path = os.path.join(d, "notes.csv")
    notes = []
    if os.path.isfile(notes_path):
        nh, nrows = read_table(notes_path)
        nt = column(nh, nrows, ["time_s", "time", "beat_time_s", "strike_time_s"], notes_path)
        nhand = column(nh, nrows, ["hand"], notes_path, convert=hand_value)
        nnuance = column(nh, nrows, ["nuance"], notes_path, convert=str.strip, required=False)
        ntempo = column(nh, nrows, ["tempo_bpm", "tempo"], notes_path, required=False)
        for k in range(len(nt)):
            notes.append({"time_s": nt[k], "hand": nhand[k],
                          "nuance": nnuance[k] if nnuance else "",
                          "tempo": ntempo[k] if ntempo else None})
    else:
        print("figure5: %s missing: no score row" % notes_path)

    strikes_path = os.path.join(d, "strikes.csv")
    sh, srows = read_table(strikes_path)
    strikes = [{"time_s": float(r[sh.index("time_s")]),
                "hand": "left" if int(r[sh.index("hand")]) == 0 else "right",
                "bounce": int(r[sh.index("bounce")]),
                "velocity": float(r[sh.index("normal_velocity_mps")])} for r in srows]
    drum_y = None
    try:
        with open(os.path.join(d, "render.json")) as f:
            drum_y = float(json.load(f)["drum"]["center_m"][1])
    except (OSError, KeyError, ValueError, IndexError, TypeError):
        pass

    # The sticks' fulcrum angles (the stick turning in the hand), when tips.csv has them.
    fulcrum = {}
    for hand in HANDS:
        name = "%s_fulcrum_rad" % hand
        if name in header:
            fulcrum[hand] = np.degrees(np.array([float(r[header.index(name)]) for r in rows]))
    panels = [1.2, 4, 1.6, 1] if fulcrum else [1.2, 4, 1]
    axes = plt.subplots(len(panels), 1, sharex=True, figsize=(11, 6.5 + (1.5 if fulcrum else 0)),
                        gridspec_kw={"height_ratios": panels})[1]
    fig = axes[0].figure
    ax_score, ax_tips = axes[0], axes[1]
    ax_fulcrum = axes[2] if fulcrum else None
    ax_strikes = axes[-1]
    if fulcrum:
        for hand, angle in fulcrum.items():
            ax_fulcrum.plot(t, angle, "-", color=COLOURS[hand], lw=1.0, label="%s fulcrum" % hand)
        ax_fulcrum.axhline(0.0, color="0.5", lw=0.6)
        ax_fulcrum.set_ylabel("fulcrum (deg)")
        ax_fulcrum.legend(fontsize=7, ncol=2, loc="upper right")
        ax_fulcrum.grid(alpha=0.3)
    # The score: one row per hand, the nuance written at each note; tempo above.
    for hand, row in (("right", 1), ("left", 0)):
        hn = [n for n in notes if n["hand"] == hand]
        ax_score.scatter([n["time_s"] for n in hn], [row] * len(hn), marker="|", s=200,
                         color=COLOURS[hand])
        for n in hn:
            ax_score.annotate(SHORT.get(n["nuance"], n["nuance"]), (n["time_s"], row),
                              xytext=(2, 4), textcoords="offset points", fontsize=7, rotation=30)
    tempos = [(n["time_s"], n["tempo"]) for n in notes if n["tempo"] is not None]
    last, last_t = None, -1e9
    for tm, bpm in tempos:  # at each change, at most one label per second
        if last is None or (abs(bpm - last) >= 0.5 and tm - last_t >= 1.0):
            ax_score.annotate("%.0f bpm" % bpm, (tm, 2.3), fontsize=7, color="0.3")
            last, last_t = bpm, tm
    ax_score.set_yticks([0, 1])
    ax_score.set_yticklabels(["L", "R"])
    ax_score.set_ylim(-0.5, 2.8)
    ax_score.set_title(args.title)
    # Tip heights: simulated solid, target dotted; strikes marked on the curve.
    for hand in HANDS:
        c = COLOURS[hand]
        if (hand, "target") in height:
            ax_tips.plot(t, height[(hand, "target")], ":", color=c, lw=1,
                         label="%s target" % hand)
        ax_tips.plot(t, height[(hand, "sim")], "-", color=c, lw=1.3, label="%s tip" % hand)
        for bounce in (0, 1):
            st = [s["time_s"] for s in strikes if s["hand"] == hand and s["bounce"] == bounce]
            if st:
                ax_tips.plot(st, np.interp(st, t, height[(hand, "sim")]),
                             "o" if bounce == 0 else "x", color=c, ms=5 if bounce == 0 else 6,
                             mfc=c if bounce == 0 else "none",
                             label="%s %s" % (hand, "bounce" if bounce else "strike"))
    if drum_y is not None:
        ax_tips.axhline(drum_y, color="0.5", lw=0.8, ls="--", label="drum head")
    # headroom above the highest lift for the legend
    top = max(float(np.max(v)) for v in height.values())
    bottom = min(float(np.min(v)) for v in height.values())
    ax_tips.set_ylim(bottom - 0.03 * (top - bottom), top + 0.3 * (top - bottom))
    ax_tips.set_ylabel("tip height (m)")
    ax_tips.legend(fontsize=7, ncol=4, loc="upper right")
    ax_tips.grid(alpha=0.3)
    # The strike list: a raster per hand, marker size by normal velocity.
    for hand, row in (("right", 1), ("left", 0)):
        hs = [s for s in strikes if s["hand"] == hand]
        ax_strikes.scatter([s["time_s"] for s in hs], [row] * len(hs),
                           s=[8 + 6 * max(0.0, s["velocity"]) for s in hs],
                           c=[COLOURS[hand] if not s["bounce"] else "none" for s in hs],
                           edgecolors=COLOURS[hand], linewidths=0.8)
    ax_strikes.set_yticks([0, 1])
    ax_strikes.set_yticklabels(["L", "R"])
    ax_strikes.set_ylim(-0.6, 1.6)
    ax_strikes.set_ylabel("strikes")
    ax_strikes.set_xlabel("time (s)")
    fig.tight_layout()
    fig.savefig(stem + ".png", dpi=120)
    fig.savefig(stem + ".svg")
    plt.close(fig)

    primary = [s for s in strikes if not s["bounce"]]
    print("figure5: %d notes, %d strikes (%d primary, %d bounces)"
          % (len(notes), len(strikes), len(primary), len(strikes) - len(primary)))
    if notes:
        # Each note's nearest primary strike of its hand (docs/perform.md: within +-5 ms).
        errors = []
        for n in notes:
            cand = [s["time_s"] for s in primary if s["hand"] == n["hand"]]
            if cand:
                errors.append(min(cand, key=lambda x: abs(x - n["time_s"])) - n["time_s"])
        if errors:
            e = np.abs(np.array(errors)) * 1000.0
            print("figure5: strike - note time: max %.2f ms, mean %.2f ms over %d notes"
                  % (e.max(), e.mean(), len(errors)))
    print("figure5: wrote %s.png and %s.svg" % (stem, stem))


if __name__ == "__main__":
    main()
