#!/usr/bin/env python3
"""Drags played soft and on time: seeded scores of drags (docs/score.md, "Flams, drags and
rolls") over tempi, note dynamics mf..ff, nuances, both grips and both hands, a third of them on
`--kit standard`'s snare, rendered by the real `ictusd render` and judged by
ictus_tools.render_check against times computed here (beat * 60 / bpm, the graces 70 and 30 ms
before their note): every note and grace one primary strike within +-5 ms, no extra primary.
And each drag's two graces are soft:

- each grace's impact speed at most GRACE_TO_NOTE of its note's. A grace is legato at dynamics
  0.15 (kGraceDynamics), the note here 0.6..1.0: by the dynamics rule of docs/gestures.md
  (speed ~ d^1.3) a grace is 0.165 of an mf note; half leaves room for the rebound below.
- the two graces within PAIR_RATIO of each other. The first comes from a whole stroke at the
  grace's dynamics (~0.5 m/s); the second, 40 ms later, from the rebound: for it to be a stroke,
  not a bounce, the hand must lift the stick more than 1 cm between the two (docs/osc.md,
  "Bounce"). With the first's ~5 ms contact that leaves ~35 ms to rise 1 cm and fall back: falling
  1 cm from rest in half of it at a constant acceleration meets the head at 2 h / t = 1.14 m/s,
  2.3 times the first. A drag's second grace cannot be softer than that by much; 2.75 allows
  20 % over it. (Before the floored rebound strokes kept their speed, the second grace hit at
  1.5-1.9 m/s, 3.1-3.8 times the first.)

    PYTHONPATH=python python3 tests/perform/test_drags.py --ictusd build/ictusd --count 12
"""
import argparse
import os
import random
import sys
from concurrent.futures import ThreadPoolExecutor

from ictus_tools import render_check

GRACE_TO_NOTE = 0.5
PAIR_RATIO = 2.75
FLAM_LEAD_S = 0.030        # docs/score.md: the second grace 30 ms before the note
DRAG_SPACING_S = 0.040     # and the first 40 ms before that
GRACE_DYNAMICS = 0.15
DYNAMICS = [("mf", 0.6), ("f", 0.8), ("ff", 1.0), ("0.7", 0.7), ("0.9", 0.9)]
NUANCES = ["legato", "accent", "staccato", "tenuto"]
DEFAULT_THETA = {"right": 180.0, "left": 0.0}


class DragScore:
    """A seeded score of drags: `text`, `notes` (render_check's expected notes), `kit`."""

    def __init__(self, seed):
        rng = random.Random(seed)
        self.seed = seed
        self.kit = "standard" if seed % 3 == 0 else None
        grip = rng.choice(["french", "german"])
        self.physical_grip = grip
        # Alternating drags (R drag, L drag) in 8ths at 75..150 bpm, as drummers practise them;
        # or drags of one hand, a note or a rest apart, at 60..180 bpm.
        alternating = rng.random() < 0.5
        tempo = round(rng.uniform(75, 150) if alternating else rng.uniform(60, 180), 1)
        beats = 0.5 if alternating else 1.0
        first = rng.choice(["R", "L"])
        count = rng.randint(4, 6)
        word, dyn = rng.choice(DYNAMICS)
        lines = ["# drags, seed %d" % seed, "tempo %g" % tempo, "grip %s" % grip,
                 "beats %s" % ("1/2" if alternating else "1"), "dynamics %s" % word]
        if self.kit:
            lines.append("drum snare")
        notes = []
        beat = 0.0
        for k in range(count):
            hand = first if not alternating or k % 2 == 0 else {"R": "L", "L": "R"}[first]
            nuance = rng.choice(NUANCES)
            line = len(lines) + 1
            lines.append("%s %s drag" % (hand, nuance))
            t = beat * 60.0 / tempo
            name = "right" if hand == "R" else "left"
            other = "left" if name == "right" else "right"
            note = self._note(t, name, nuance, grip, dyn, beats, tempo, line, None)
            for lead in (FLAM_LEAD_S + DRAG_SPACING_S, FLAM_LEAD_S):
                g = self._note(t - lead, other, "legato", grip, min(GRACE_DYNAMICS, 0.5 * dyn),
                               0.0, tempo, line, "drag")
                g["principal"] = note
                notes.append(g)
            notes.append(note)
            beat += beats
            if not alternating and rng.random() < 0.5:
                lines.append("rest")
                beat += beats
        self.text = "\n".join(lines) + "\n"
        notes.sort(key=lambda n: (n["time_s"], n["hand"] != "right"))
        self.notes = notes

    def _note(self, t, hand, nuance, grip, dyn, beats, tempo, line, grace):
        n = {"time_s": t, "hand": hand, "nuance": nuance, "grip": grip, "dynamics": dyn,
             "beats": beats, "tempo_bpm": tempo, "r_over_a": 0.3, "theta_deg": DEFAULT_THETA[hand],
             "line": line, "grace": grace}
        if self.kit:
            n["drum"] = "snare"
        return n

    def write(self, path):
        with open(path, "w") as f:
            f.write(self.text)


def grace_speed_problems(res):
    """Each drag's graces against its note (GRACE_TO_NOTE) and each other (PAIR_RATIO). Returns
    (problems, [(first, second, note) speeds])."""
    problems, pairs = [], []
    recs = res.notes  # in time order, each with its strike
    for i, r in enumerate(recs):
        if r["grace"] != "drag" or i + 1 >= len(recs) or recs[i + 1]["grace"] != "drag":
            continue
        a, b = r, recs[i + 1]
        note = next((n for n in recs if not n["grace"]
                     and abs(n["time_s"] - (a["time_s"] + FLAM_LEAD_S + DRAG_SPACING_S)) < 1e-9), None)
        if not (note and a["strike"] and b["strike"] and note["strike"]):
            continue  # render_check counts a missed note
        va, vb = a["strike"]["normal_velocity_mps"], b["strike"]["normal_velocity_mps"]
        vn = note["strike"]["normal_velocity_mps"]
        pairs.append((va, vb, vn))
        where = "drag of the %s note at %.3f s (line %d)" % (note["hand"], note["plan_time_s"],
                                                              note["line"])
        for name, v in (("first", va), ("second", vb)):
            if v > GRACE_TO_NOTE * vn:
                problems.append("%s: %s grace %.2f m/s, over %.2f of its note's %.2f m/s"
                                % (where, name, v, GRACE_TO_NOTE, vn))
        if max(va, vb) > PAIR_RATIO * min(va, vb):
            problems.append("%s: graces %.2f and %.2f m/s, %.2f times apart (at most %.2f)"
                            % (where, va, vb, max(va, vb) / min(va, vb), PAIR_RATIO))
    return problems, pairs


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ictusd", required=True)
    ap.add_argument("--first", type=int, default=1)
    ap.add_argument("--count", type=int, default=12)
    ap.add_argument("--workdir", default="drags-out")
    ap.add_argument("--jobs", type=int, default=max(1, min(2, os.cpu_count() or 1)))
    ap.add_argument("--print", type=int, metavar="SEED", help="print drag score SEED and exit")
    a = ap.parse_args()
    if a.print is not None:
        sys.stdout.write(DragScore(a.print).text)
        return 0

    def one(seed):
        score = DragScore(seed)
        res = render_check.render(a.ictusd, score, a.workdir)
        res.pairs = []
        if res.notes:
            problems, res.pairs = grace_speed_problems(res)
            res.problems.extend(problems)
        return res

    with ThreadPoolExecutor(max_workers=a.jobs) as ex:
        results = list(ex.map(one, range(a.first, a.first + a.count)))
    failed = [r for r in results if not r.ok]
    for r in failed:
        kit = " --kit " + r.score.kit if r.score.kit else ""
        print("\n".join(
            "  reproduce: PYTHONPATH=python python3 %s --print %d > s.txt && %s render%s --score "
            "s.txt --out out-%d" % (sys.argv[0], r.seed, a.ictusd, kit, r.seed)
            if line.startswith("  reproduce:") else line for line in r.report(a.ictusd).split("\n")))
    pairs = [p for r in results for p in r.pairs]
    errors = [abs(n["error_ms"]) for r in results for n in r.notes if n["error_ms"] is not None]
    if pairs:
        print("%d drags in %d scores: first grace %.2f..%.2f m/s, second %.2f..%.2f m/s, second /"
              " first %.2f..%.2f, grace / note at most %.2f; timing error worst %.2f ms; %d failed"
              % (len(pairs), len(results), min(p[0] for p in pairs), max(p[0] for p in pairs),
                 min(p[1] for p in pairs), max(p[1] for p in pairs),
                 min(p[1] / p[0] for p in pairs), max(p[1] / p[0] for p in pairs),
                 max(max(p[0], p[1]) / p[2] for p in pairs), max(errors or [float("nan")]),
                 len(failed)))
    if len(pairs) < 3 * len(results):
        print("only %d drags judged in %d scores" % (len(pairs), len(results)))
        return 1
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
