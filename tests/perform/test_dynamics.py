#!/usr/bin/env python3
"""Dynamics by stroke height, played by the real `ictusd render` (docs/gestures.md, "Dynamics rule"):
- the ladder `R legato D`, D = 0.05 .. 1.0 one second apart: impact speeds (strikes.csv, each
  note's primary strike) strictly increase with D and span at least 20x from 0.05 to 1.0
  (drummers span roughly 0.3-10 m/s by stroke height: 30x);
- the five nuances at pp, mf and ff, in both control modes: impact speed orders by dynamics
  first, every pp note slower than every mf note, every mf note slower than every ff note;
- every note one primary strike within +-5 ms (ictus_tools.render_check's acceptance), in the
  default Cartesian mode and in `--mode joint` (there the ladder's speeds are printed: its two
  softest strokes, 1.5 and 1.8 cm high, are within the joint mode's tracking noise of each other).

    PYTHONPATH=python python3 tests/perform/test_dynamics.py --ictusd build/ictusd
"""
import argparse
import sys

from ictus_tools import render_check

LADDER = [0.05, 0.1, 0.2, 0.3, 0.45, 0.6, 0.8, 1.0]
NUANCES = ["legato", "tenuto", "accent", "vertical_accent", "staccato"]
LEVELS = [("pp", 0.2), ("mf", 0.6), ("ff", 1.0)]
MIN_SPAN = 20.0  # the acceptance: ff / pp over the ladder


class Score:
    """A score of right-hand notes one second apart (tempo 60), for render_check."""

    def __init__(self, name, notes):
        self.seed = name
        self.notes = []
        lines = ["tempo 60"]
        for k, (nuance, word, dyn) in enumerate(notes):
            lines.append("R %s %s" % (nuance, word))
            self.notes.append({"time_s": float(k), "hand": "right", "nuance": nuance,
                               "grip": "french", "dynamics": dyn, "beats": 1.0,
                               "tempo_bpm": 60.0, "r_over_a": 0.3, "theta_deg": 180.0,
                               "line": k + 2})
        self.text = "\n".join(lines) + "\n"
        self.physical_grip = "french"

    def write(self, path):
        with open(path, "w") as f:
            f.write(self.text)


def speeds(ictusd, score, workdir, problems, mode="cartesian"):
    res = render_check.render(ictusd, score, workdir, extra_args=["--mode", mode])
    problems.extend("%s (%s): %s" % (score.seed, mode, p) for p in res.problems)
    print("%s mode: timing error %s ms" % (mode, ", ".join(
        "%+.1f" % n["error_ms"] if n["error_ms"] is not None else "-" for n in res.notes)))
    return [n["strike"]["normal_velocity_mps"] if n["strike"] else float("nan") for n in res.notes]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ictusd", required=True)
    ap.add_argument("--workdir", default="dynamics-out")
    a = ap.parse_args()
    problems = []
    ladder = speeds(a.ictusd, Score(1, [("legato", "%g" % d, d) for d in LADDER]), a.workdir,
                    problems)
    print("ladder: " + ", ".join("%g: %.3f m/s" % (d, v) for d, v in zip(LADDER, ladder)))
    for k in range(1, len(ladder)):
        if not ladder[k] > ladder[k - 1]:
            problems.append("ladder not monotone: %.3f m/s at %g after %.3f m/s at %g"
                            % (ladder[k], LADDER[k], ladder[k - 1], LADDER[k - 1]))
    span = ladder[-1] / ladder[0]
    print("span 1.0 / 0.05: %.1fx" % span)
    if not span >= MIN_SPAN:
        problems.append("ladder spans %.1fx, want >= %gx" % (span, MIN_SPAN))
    joint = speeds(a.ictusd, Score(3, [("legato", "%g" % d, d) for d in LADDER]), a.workdir,
                   problems, "joint")
    print("joint mode ladder: " + ", ".join("%g: %.3f m/s" % (d, v) for d, v in zip(LADDER, joint)))
    notes = [(n, w, d) for w, d in LEVELS for n in NUANCES]
    for mode in ("cartesian", "joint"):
        table = speeds(a.ictusd, Score(2 if mode == "cartesian" else 4, notes), a.workdir,
                       problems, mode)
        by_level = {}
        for (n, w, _), v in zip(notes, table):
            by_level.setdefault(w, []).append(v)
            print("%-9s %-16s %s %.3f m/s" % (mode, n, w, v))
        for (lo, _), (hi, _) in zip(LEVELS, LEVELS[1:]):
            if not max(by_level[lo]) < min(by_level[hi]):
                problems.append("%s mode: every %s not slower than every %s: %s max %.3f, %s min %.3f"
                                % (mode, lo, hi, lo, max(by_level[lo]), hi, min(by_level[hi])))
    for p in problems:
        print("FAIL: " + p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
