#!/usr/bin/env python3
"""Any valid score plays right: seeded random scores in the whole score language
(ictus_tools.random_score: tempi 40..220 bpm and ramps, every fraction with triplets and dotted
values, rests, R+L, both grips, every nuance the parser knows, pp..ff and numbers, `at`,
repeats), each rendered by the real `ictusd render`, in parallel over the cores. For every
score (ictus_tools.render_check):

- ictusd accepts it (the generator keeps the planner's rule: strokes of one hand >= 0.1 s apart);
- notes.csv holds exactly the generator's notes, at the times of the generator's own tempo map
  (closed-form integral, written again in Python) plus the lead-in;
- every note gets exactly one primary (non-bounce) strike of its hand within +-5 ms of its beat,
  and there is no other primary strike;
- no NaN or infinity in strikes.csv, notes.csv, tips.csv or render.json;
- bounce rows are tagged consistently (the bounce window and stroke numbers in strikes.csv, the
  tip's height between contacts in tips.csv);
- joint limits, where render.json reports them (performance.joint_limits.max_excursion_deg):
  no excursion beyond 2 deg; the trunk's amplitude, where reported, is printed.

A failure prints the seed, the score, the offending notes and the command that reproduces it.

usage: test_random_scores.py --ictusd BUILD/ictusd [--first 1] [--count 100 | --seeds A,B,..] [--jobs N]
                             [--workdir DIR] [--keep]
The renders go to DIR (default: a temporary folder), emptied first; those of failing scores are
kept there (all of them with --keep).
"""
import argparse
import os
import shutil
import sys
import time

from ictus_tools import checks, random_score, render_check
from ictus_tools.checks import check, fail


def main():
    ap = argparse.ArgumentParser()
    render_check.seed_arguments(ap, 100, "the coverage check is then skipped (a handful of "
                                "seeds need not hold every nuance)")
    args = ap.parse_args()

    if not os.access(args.ictusd, os.X_OK):
        fail("no ictusd at %s" % args.ictusd)
    nuances = random_score.nuance_list(args.ictusd)
    print("nuances from the parser: %s" % ", ".join(nuances))

    # The generator is deterministic and draws what it claims to (checked on the test's own
    # seeds: every nuance and both grips must appear, or the test would miss them silently).
    seeds = render_check.seeds_of(args)
    scores = [random_score.RandomScore(s, nuances) for s in seeds]
    again = random_score.RandomScore(seeds[0], nuances)
    problems = []
    if again.text != scores[0].text:
        problems.append("the generator is not deterministic: seed %d gave two texts" % seeds[0])
    drawn = {"nuance": set(), "grip": set(), "both": set()}
    for sc in scores:
        for n in sc.notes:
            drawn["nuance"].add(n["nuance"])
            drawn["grip"].add(n["grip"])
            drawn["both"].add(n["both"])
    for name, want in (("nuance", set(nuances)), ("grip", {"french", "german"}),
                       ("both", {True, False})):
        if drawn[name] != want and not args.seeds:
            problems.append("the %d scores do not cover every %s: %s of %s"
                            % (len(scores), name, sorted(map(str, drawn[name])), sorted(map(str, want))))

    # The check finds planted faults: a render of the first seed that plays right, with one
    # strike removed, moved, made NaN, re-tagged, or added (render_check.planted_faults).
    jobs = args.jobs or os.cpu_count() or 2
    t0 = time.monotonic()
    workdir = render_check.empty_workdir(args.workdir, "ictus-random-scores-")
    results, _ = render_check.run_many(args.ictusd, seeds, workdir=workdir, jobs=jobs,
                                       nuances=nuances, keep=args.keep,
                                       progress=render_check.progress_printer(t0))
    wall = time.monotonic() - t0
    notes = sum(len(r.notes) for r in results)
    failed = [r for r in results if not r.ok]
    simulated = sum(r.simulated_s for r in results)
    print("%d scores, %d notes, %.0f s simulated, rendered in %.1f s wall with %d jobs"
          % (len(results), notes, simulated, wall, jobs))
    limits = [r.joint_limits_deg for r in results if r.joint_limits_deg is not None]
    if limits:
        print("joint limits: largest excursion %.2f deg (bound %.1f)"
              % (max(limits), render_check.MAX_LIMIT_EXCURSION_DEG))
    trunk = [(r.seed, p, v) for r in results for p, v in r.trunk if isinstance(v, (int, float))]
    if trunk:
        worst = max(trunk, key=lambda x: x[2])
        print("trunk: %d values reported, largest %s = %.4g (seed %d)" % (len(trunk), worst[1],
                                                                           worst[2], worst[0]))
    for r in failed:
        print(r.report(args.ictusd))
        print("  (render kept in %s)" % os.path.join(workdir, "seed-%d" % r.seed))
    if failed:
        bad_notes = sum(len(r.failing_notes()) for r in failed)
        extra = sum(len(r.extra) for r in failed)
        problems.append("%d of %d scores not played right (%d of %d notes, %d extra primary "
                        "strikes): seeds %s" % (len(failed), len(results), bad_notes, notes, extra,
                                                " ".join(str(r.seed) for r in failed)))
    good = next((r for r in results if r.ok), None)
    if good is None:
        problems.append("no score played right: the planted-fault check has nothing to plant in")
    else:
        out = os.path.join(workdir, "planted", "seed-%d" % good.seed)
        again = render_check.render(args.ictusd, good.score, os.path.join(workdir, "planted"))
        if not again.ok:
            problems.append("seed %d played right once and not again: %s" % (good.seed, again.problems))
        else:
            for name, found, why in render_check.planted_faults(good.score, os.path.join(out, "out")):
                print("planted fault in seed %d, %s: %s" % (good.seed, name, "found" if found else
                                                          "NOT FOUND (%s)" % "; ".join(why)))
                if not found:
                    problems.append("the check did not find a planted fault: " + name)
            shutil.rmtree(os.path.join(workdir, "planted"), ignore_errors=True)
    if not failed and not args.keep:
        shutil.rmtree(workdir, ignore_errors=True)
    checks.keep_going()  # every problem is reported
    for p in problems:
        check(False, p)
    checks.finish()
    print("PASS: every note of %d random scores got one primary strike within +-%g ms, no "
          "extra primary strike" % (len(results), render_check.TOLERANCE_MS))
    return 0


if __name__ == "__main__":
    sys.exit(main())
