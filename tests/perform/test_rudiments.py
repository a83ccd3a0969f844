#!/usr/bin/env python3
"""Seeded rudiment scores (ictus_tools.rudiments) played by the real `ictusd render` and judged by
ictus_tools.render_check against the generator's own note times: every written note one primary
strike of its hand within +-5 ms, no extra primary strike. Doubles and paradiddles at mf (and
the other dynamics: every note of a same-hand pair is judged alike) also keep the second impact
speed of each same-hand pair within 20 % of the first. Prints the timing-error p99 and worst.

    PYTHONPATH=python python3 tests/perform/test_rudiments.py --ictusd build/ictusd --count 60
"""
import argparse
import os
import sys

from ictus_tools.rudiments import percentile, play


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
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
