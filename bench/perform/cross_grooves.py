#!/usr/bin/env python3
"""How the drummer plays grooves that cross the kit: seeded scores in the score language on
`ictusd render --kit full`, each note of the hands counted off when it is lost or struck more
than 5 ms from its time. A measurement, not a test: what it prints is in docs/kit.md ("Beyond
the arm's reach").

Each groove draws its tempo (70-140 bpm) and 2-4 bars; each bar keeps time in 8ths on the
hi-hat or the ride with the right hand (the left's snare on 2 and 4), the kick on 1 and 3, a
`R on crash` on some downbeats, and ends, in its last bar and at random in others, in a fill of
16ths over the snare and the toms (R L R L ...); the groove ends on `R on crash` with the kick.
Dynamics at random, pp..ff.

    PYTHONPATH=python python3 bench/perform/cross_grooves.py --ictusd build/ictusd --seeds 1-60
"""
import argparse
import csv
import json
import os
import random
import subprocess
import sys
import tempfile

from ictus_tools import e2e_util, limb_clearance

DYN = ["pp", "p", "mp", "mf", "f", "ff"]
TOL_MS = 5.0


def groove(seed):
    """The score text of `seed`."""
    r = random.Random(seed)
    lines = ["# cross-reach groove, seed %d" % seed, "tempo %d" % r.randint(70, 140),
             "grip french"]
    bars = r.randint(2, 4)
    for bar in range(bars):
        keep = r.choice(["hihat", "ride"])
        fill = bar == bars - 1 or r.random() < 0.3
        for eighth in range(8):
            if fill and eighth >= 4:
                break
            parts = ["R on %s 1/2 %s" % (keep, r.choice(DYN))]
            if eighth in (2, 6):
                parts.append("L on snare 1/2 %s" % r.choice(DYN))
            if eighth == 0 and bar > 0 and r.random() < 0.6:
                parts = (["R on crash 1/2 %s" % r.choice(DYN)] +
                         [p for p in parts if p.startswith("L on snare")])
            if eighth in (0, 4):
                parts.append("RF 1/2 %s" % r.choice(DYN))
            lines.append(" + ".join(parts))
        if fill:
            toms = ["snare", "tom1", "tom2", "floor"]
            for k in range(8):
                lines.append("%s on %s 1/4 %s" % ("R" if k % 2 == 0 else "L", r.choice(toms),
                                                  r.choice(DYN)))
    lines.append("R on crash 1/1 %s + RF" % r.choice(DYN))
    return "\n".join(lines) + "\n"


def score(out):
    """(notes of the hands, [notes off], stick parts through a piece, least limb core mm,
    whips, runaways)."""
    with open(os.path.join(out, "notes.csv")) as f:
        notes = [n for n in csv.DictReader(f) if n["hand"] in ("left", "right")]
    off = []
    for n in notes:
        lost = n["strike_seq"] == "-1"
        if lost or abs(float(n["error_ms"])) > TOL_MS:
            off.append("%s %s %.2f s %s" % (n["hand"], n["drum"], float(n["time_s"]),
                                            "lost" if lost else "%+.0f ms" % float(n["error_ms"])))
    with open(os.path.join(out, "render.json")) as f:
        rj = json.load(f)
    passes = sum(d.get("shell_passes", 0) for d in rj["kit"]["drums"])
    core = min(c.core_m for c in limb_clearance.clearances(out).values())
    perf = rj["performance"]
    return len(notes), off, passes, 1e3 * core, perf.get("whips", 0), perf.get("runaways", 0)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ictusd", required=True)
    ap.add_argument("--seeds", type=e2e_util.seed_range, default=e2e_util.seed_range("1-60"))
    ap.add_argument("--workdir", default=None)
    a = ap.parse_args()
    work = a.workdir or tempfile.mkdtemp(prefix="ictus-cross-grooves-")
    os.makedirs(work, exist_ok=True)
    total = {"notes": 0, "off": 0, "crashes": 0, "passes": 0, "into": 0, "whips": 0}
    print("| seed | notes | off | stick passes | limb core mm | whips | notes off |")
    print("|---|---|---|---|---|---|---|")
    for seed in a.seeds:
        path = os.path.join(work, "groove%d.txt" % seed)
        with open(path, "w") as f:
            f.write(groove(seed))
        out = os.path.join(work, "groove%d" % seed)
        run = subprocess.run([a.ictusd, "render", "--score", path, "--kit", "full", "--out", out,
                              "--force", "--progress-every", "0"], capture_output=True,
                             text=True, timeout=900)
        if run.returncode != 0:
            print("| %d | render failed: %s |" % (seed, run.stderr[-300:]))
            continue
        n, off, passes, core, whips, runaways = score(out)
        total["notes"] += n
        total["off"] += len(off)
        total["crashes"] += sum(" crash " in o for o in off)
        total["passes"] += passes
        total["into"] += core < -5.5
        total["whips"] += whips + runaways
        print("| %d | %d | %d | %d | %.1f | %d | %s |"
              % (seed, n, len(off), passes, core, whips + runaways,
                 "; ".join(off[:4]) + (" ..." if len(off) > 4 else "")))
    print("\n%(off)d of %(notes)d notes of the hands off or lost (%(crashes)d of them crashes); "
          "%(passes)d stick parts through a piece; %(into)d grooves with a limb's core over "
          "5.5 mm into a piece; %(whips)d whips or runaways" % total)
    return 0


if __name__ == "__main__":
    sys.exit(main())
