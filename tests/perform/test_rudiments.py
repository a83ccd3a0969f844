#!/usr/bin/env python3
"""Seeded rudiment scores (ictus_tools.rudiments) played by the real `ictusd render` and judged by
ictus_tools.render_check against the generator's own note times: every written note and every
grace stroke one primary strike of its hand within +-5 ms, no extra primary strike. Each grace
stroke of a flam or a drag strikes 10..45 ms before the stroke it leads into (its note, or a
drag's second grace), and notes.csv marks exactly the grace strokes. Doubles, paradiddles and
double-stroke rolls also keep the second impact speed of each same-hand pair within 20 % of the
first. Prints the timing-error p99 and worst, and the grace leads' range.

    PYTHONPATH=python python3 tests/perform/test_rudiments.py --ictusd build/ictusd --count 60
"""
import argparse
import copy
import os
import shutil
import sys

from ictus_tools.rudiments import grace_problems, percentile, play


def planted(results, workdir):
    """The grace checks can fail: on a copy of a render with grace strokes that played right, a
    grace struck 20 ms earlier, and notes.csv's grace column cleared, must each be named."""
    res = next((r for r in results if r.ok and r.grace_leads_ms), None)
    if res is None:
        return ["no render with grace strokes played right to plant faults in"]
    out = os.path.join(workdir, "seed-%d" % res.seed, "out")
    moved = copy.deepcopy(res)
    g = next(n for n in moved.notes if n["grace"] and n["strike"])
    g["strike"]["time_s"] -= 0.020
    missing = []
    if not any("struck" in p for p in grace_problems(moved, out)[0]):
        missing.append("a grace struck 20 ms early was not named")
    cleared = out + "-planted-grace"
    shutil.rmtree(cleared, ignore_errors=True)
    shutil.copytree(out, cleared)
    with open(os.path.join(out, "notes.csv")) as f:
        text = f.read().replace(",1\n", ",0\n")
    with open(os.path.join(cleared, "notes.csv"), "w") as f:
        f.write(text)
    if not any("notes.csv row" in p for p in grace_problems(res, cleared)[0]):
        missing.append("notes.csv without its grace marks was not named")
    shutil.rmtree(cleared, ignore_errors=True)
    return missing


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ictusd", required=True)
    ap.add_argument("--first", type=int, default=1)
    ap.add_argument("--count", type=int, default=60)
    ap.add_argument("--workdir", default="rudiments-out")
    ap.add_argument("--jobs", type=int, default=max(1, min(2, os.cpu_count() or 1)))
    ap.add_argument("--same-hand-ms", type=float,
                    help="doubles at mf with this same-hand interval only (the limit's measure)")
    a = ap.parse_args()
    seeds = list(range(a.first, a.first + a.count))
    forced = a.same_hand_ms / 1000.0 if a.same_hand_ms else None
    results = play(a.ictusd, seeds, a.workdir, a.jobs, forced)
    errors = [abs(n["error_ms"]) for r in results for n in r.notes if n["error_ms"] is not None]
    failed = [r for r in results if not r.ok]
    for r in failed:
        print(r.report(a.ictusd))
        print("  rudiment %s at %.1f bpm, same hand %.1f ms; the score: PYTHONPATH=python python3 -m "
              "ictus_tools.rudiments --seed %d" % (r.score.rudiment, r.score.tempo_bpm,
                                                  r.score.same_hand_s * 1000, r.seed))
    closest = min(r.score.same_hand_s for r in results)
    print("%d rudiment scores, %d notes, closest same-hand interval %.1f ms: timing error p99 %.2f ms,"
          " worst %.2f ms; %d failed" % (len(results), len(errors), closest * 1000,
                                         percentile(errors, 0.99), max(errors or [float("nan")]),
                                         len(failed)))
    leads = [x for r in results for x in getattr(r, "grace_leads_ms", [])]
    if leads:
        print("%d grace strokes: struck %.1f .. %.1f ms before the stroke they lead into"
              % (len(leads), min(leads), max(leads)))
    missing = [] if a.same_hand_ms else planted(results, a.workdir)
    for m in missing:
        print("planted fault: " + m)
    return 1 if failed or missing else 0


if __name__ == "__main__":
    sys.exit(main())
