#!/usr/bin/env python3
"""Rudiment scores through the real `ictusd render`: timing p99 and worst over many scores.

Renders N seeded rudiment scores (ictus_tools.rudiments: singles, doubles, paradiddles, flams,
flam taps, drags, double-stroke and buzz rolls at drummers' tempi, same-hand strokes down to
60 ms apart), judges each as
tests/perform/test_rudiments.py does, and prints the timing error's p50, p99 and worst (with its
seed), by rudiment, the grace strokes' leads (p1, p50, p99 before the stroke they lead into)
and the failing seeds.

usage (python/ on PYTHONPATH, docs/python.md):
       bench/rudiments.py ICTUSD [--count 500] [--first 1] [--jobs N] [--workdir DIR]
"""
import argparse
import os
import sys
import tempfile

from ictus_tools.rudiments import RUDIMENTS, percentile, play


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("ictusd")
    ap.add_argument("--count", type=int, default=500)
    ap.add_argument("--first", type=int, default=1)
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--workdir")
    a = ap.parse_args()
    workdir = a.workdir or tempfile.mkdtemp(prefix="ictus-rudiments-")
    results = play(a.ictusd, list(range(a.first, a.first + a.count)), workdir, a.jobs)
    print("| rudiment | scores | notes | p50 ms | p99 ms | worst ms (seed) | failed |")
    print("|---|---|---|---|---|---|---|")
    for name in sorted(RUDIMENTS) + ["all"]:
        rs = [r for r in results if name in ("all", r.score.rudiment)]
        errs = [(abs(n["error_ms"]), r.seed) for r in rs for n in r.notes if n["error_ms"] is not None]
        if not errs:
            continue
        worst = max(errs)
        print("| %s | %d | %d | %.2f | %.2f | %.2f (%d) | %d |"
              % (name, len(rs), len(errs), percentile([e for e, _ in errs], 0.5),
                 percentile([e for e, _ in errs], 0.99), worst[0], worst[1],
                 sum(1 for r in rs if not r.ok)))
    leads = [x for r in results for x in getattr(r, "grace_leads_ms", [])]
    if leads:
        print("grace strokes: %d, struck before the stroke they lead into p1 %.1f / p50 %.1f / "
              "p99 %.1f ms (min %.1f, max %.1f)"
              % (len(leads), percentile(leads, 0.01), percentile(leads, 0.5),
                 percentile(leads, 0.99), min(leads), max(leads)))
    failed = [r.seed for r in results if not r.ok]
    print("failing seeds: %s" % (", ".join(map(str, failed)) or "none"))
    print("renders in %s" % workdir)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
