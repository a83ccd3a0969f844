#!/usr/bin/env python3
"""Every grip firmness keeps time: scores of single strokes, doubles, 16ths, accents, flams and
drags (docs/score.md) at each firmness of 0..1 (the `firmness F` statement, or `firmness F` on
every note), both grips, seeded tempi 90..140 bpm, rendered by the real `ictusd render` and
judged by ictus_tools.render_check against times computed here (beat * 60 / bpm; a flam's grace
30 ms, a drag's 70 and 30 ms before its note): every note and grace stroke one primary strike of
its hand within +-5 ms, no extra primary strike. A loose grip changes the contact and the
rebound, not the time a drummer keeps (docs/perform.md, "Grip firmness").

    PYTHONPATH=python python3 tests/perform/test_firmness.py --ictusd build/ictusd
"""
import argparse
import os
import random
import sys
from concurrent.futures import ThreadPoolExecutor

from ictus_tools import render_check

FIRMNESS = [0.0, 0.1, 0.2, 0.25, 0.35, 0.5, 0.75, 1.0]
FLAM_LEAD_S = 0.030        # docs/score.md: a flam's grace, a drag's second
DRAG_SPACING_S = 0.040     # a drag's first grace this much before its second
GRACE_DYNAMICS = 0.15
DEFAULT_THETA = {"right": 180.0, "left": 0.0}
WORDS = {"f": 0.8, "ff": 1.0, "p": 0.3}
# (beats, strokes): a stroke is "R", "L", "R f" (dynamics), "L drag", "R flam".
PASSAGES = [
    (1.0, ["R", "L", "R", "L"]),
    (0.5, ["R", "R", "L", "L", "R f", "R f", "L ff", "L ff"]),
    (0.25, ["R", "L", "R", "L", "R", "R", "L", "L"]),
    (0.5, ["L drag", "R drag", "R flam", "L flam", "R p", "L ff", "R drag", "L"]),
]


class FirmnessScore:
    """Seeded: `firmness` (0..1), `text`, `notes` (render_check's expected notes)."""

    def __init__(self, seed, firmness):
        rng = random.Random(seed)
        self.seed = seed
        self.kit = None
        grip = ("french", "german")[seed % 2]
        self.physical_grip = grip
        per_note = seed % 4 >= 2  # `firmness F` on every note instead of the statement
        tempo = round(rng.uniform(90, 140), 1)
        ftext = ("%.2f" % firmness).rstrip("0").rstrip(".")
        lines = ["# firmness %s, seed %d" % (ftext, seed), "tempo %g" % tempo, "grip " + grip]
        if not per_note:
            lines.append("firmness " + ftext)
        notes, beat = [], 0.0
        for beats, strokes in PASSAGES:
            lines.append("beats %s" % {1.0: "1", 0.5: "1/2", 0.25: "1/4"}[beats])
            line = len(lines) + 1
            words = []
            for k, w in enumerate(strokes):
                parts = w.split()
                hand = "right" if parts[0] == "R" else "left"
                dyn = WORDS.get(parts[1], 0.6) if len(parts) > 1 else 0.6
                orn = parts[1] if len(parts) > 1 and parts[1] in ("flam", "drag") else None
                words.append(w + (" firmness " + ftext if per_note else ""))
                t = beat * 60.0 / tempo
                other = "left" if hand == "right" else "right"
                leads = {"flam": [FLAM_LEAD_S], "drag": [FLAM_LEAD_S + DRAG_SPACING_S,
                                                         FLAM_LEAD_S]}.get(orn, [])
                for lead in leads:
                    notes.append(self._note(t - lead, other, grip, min(GRACE_DYNAMICS, 0.5 * dyn),
                                            0.0, tempo, line))
                notes.append(self._note(t, hand, grip, dyn, beats, tempo, line))
                beat += beats
            lines.append(", ".join(words))
        self.text = "\n".join(lines) + "\n"
        notes.sort(key=lambda n: (n["time_s"], n["hand"] != "right"))
        self.notes = notes

    @staticmethod
    def _note(t, hand, grip, dyn, beats, tempo, line):
        return {"time_s": t, "hand": hand, "nuance": "legato", "grip": grip, "dynamics": dyn,
                "beats": beats, "tempo_bpm": tempo, "r_over_a": 0.3,
                "theta_deg": DEFAULT_THETA[hand], "line": line}

    def write(self, path):
        with open(path, "w") as f:
            f.write(self.text)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ictusd", required=True)
    ap.add_argument("--seeds", type=int, default=2, help="renders per firmness (seeds 1..N)")
    ap.add_argument("--one-each", action="store_true",
                    help="one render per firmness, seeds 1 and 2 in turn (both grips, the "
                    "statement and the per-note word, each over four firmnesses)")
    ap.add_argument("--workdir", default="firmness-out")
    ap.add_argument("--jobs", type=int, default=max(1, min(2, os.cpu_count() or 1)))
    ap.add_argument("--print", nargs=2, type=float, metavar=("SEED", "FIRMNESS"),
                    help="print the score of SEED at FIRMNESS and exit")
    a = ap.parse_args()
    if a.print:
        sys.stdout.write(FirmnessScore(int(a.print[0]), a.print[1]).text)
        return 0
    if a.one_each:
        cases = [(i * 100 + 1 + i % 2, f) for i, f in enumerate(FIRMNESS)]
    else:
        cases = [(i * 100 + s, f) for i, f in enumerate(FIRMNESS) for s in range(1, a.seeds + 1)]

    def one(case):
        seed, f = case
        return f, render_check.render(a.ictusd, FirmnessScore(seed, f), a.workdir)

    with ThreadPoolExecutor(max_workers=a.jobs) as ex:
        results = list(ex.map(one, cases))
    failed = [(f, r) for f, r in results if not r.ok]
    for f, r in failed:
        print("firmness %g: %s" % (f, "\n".join(
            "  reproduce: PYTHONPATH=python python3 %s --print %d %g > s.txt && %s render --score "
            "s.txt --out out-%d" % (sys.argv[0], r.seed, f, a.ictusd, r.seed)
            if line.startswith("  reproduce:") else line for line in r.report(a.ictusd).split("\n"))))
    for f in FIRMNESS:
        errs = [abs(n["error_ms"]) for g, r in results if g == f for n in r.notes
                if n["error_ms"] is not None]
        bad = sum(len(r.failing_notes()) for g, r in results if g == f)
        total = sum(len(r.notes) for g, r in results if g == f)
        print("firmness %-4g: %d of %d notes not played right, worst timing error %.2f ms"
              % (f, bad, total, max(errs or [float("nan")])))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
