#!/usr/bin/env python3
"""Random scores through the real `ictusd render`: how well any valid score is played.

Renders N seeded random scores (ictus_tools.random_score; seeds FIRST .. FIRST+N-1) with the
given ictusd, in parallel, checks each as tests/perform/test_random_scores.py does
(ictus_tools.render_check), and prints the distribution as markdown, ready for docs/perform.md:
notes, missed notes, extra primary strikes, bounces, timing error (mean, p50, p99, worst and its
seed), contact duration (median, p5/p95), measured / planned impact speed, and the notes not
played right by score feature (tempo band, fraction, grip, nuance, dynamics, ...) so that weak
spots show; then the failing seeds.

A note is *right* when exactly one primary strike of its hand lands within +-5 ms of its beat.
For the statistics each note gets its nearest primary strike within 50 ms (closer to it than to
the hand's neighbouring notes): *off-time* when that strike is beyond 5 ms, *missed* when there
is none; primary strikes given to no note are *extra*.

With `--kit full`: random scores over that kit (random_score's kit mode, rendered with
`--kit full`; tests/perform/test_random_kit_scores.py), the notes also by limb and drum; a kick
is right within 0.5 ms.

usage: bench/random_scores.py ICTUSD [--count 1000] [--first 1] [--jobs N] [--json FILE]
                              [--workdir DIR] [--kit full] [-- extra ictusd render options]
"""
import argparse
import json
import math
import os
import sys
import time

# Run by hand: the one bootstrap that finds the helpers' package (python/ in this repository).
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
from ictus_tools import random_score, render_check  # noqa: E402


def pct(values, p):
    """The p-th percentile, linear between order statistics (numpy's default)."""
    v = sorted(values)
    if not v:
        return float("nan")
    x = (len(v) - 1) * p / 100.0
    lo = int(math.floor(x))
    hi = min(lo + 1, len(v) - 1)
    return v[lo] + (v[hi] - v[lo]) * (x - lo)


def mean(values):
    return sum(values) / len(values) if values else float("nan")


FEATURES = ["tempo", "ramp", "fraction", "grip", "sticks' grip", "nuance", "previous stroke",
            "dynamics", "hands", "at",
            "gap before (s)", "gap after (s)", "other hand before (s)"]
ORDER = {
    "tempo": ["40-69", "70-99", "100-129", "130-159", "160-189", "190-220"],
    "gap before (s)": ["first", "0.10-0.15", "0.15-0.2", "0.2-0.3", "0.3-0.5", "0.5-1", "1-2", ">=2"],
    "gap after (s)": ["0.10-0.15", "0.15-0.2", "0.2-0.3", "0.3-0.5", "0.5-1", "1-2", ">=2", "last"],
    "other hand before (s)": ["none", "<0.03", "0.03-0.1", ">=0.1"],
}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("ictusd")
    ap.add_argument("--count", type=int, default=1000)
    ap.add_argument("--first", type=int, default=1)
    ap.add_argument("--jobs", type=int, default=0)
    ap.add_argument("--json", help="write every note's record here")
    ap.add_argument("--workdir", help="keep the failing renders here")
    ap.add_argument("--kit", help="random scores over this kit (full)")
    # The render options after "--" are split off here: argparse gives a trailing
    # nargs="*" positional nothing once the first positional (ictusd) is taken.
    argv = sys.argv[1:]
    cut = argv.index("--") if "--" in argv else len(argv)
    args = ap.parse_args(argv[:cut])
    args.render_args = argv[cut + 1:]

    nuances = random_score.nuance_list(args.ictusd)
    seeds = list(range(args.first, args.first + args.count))
    jobs = args.jobs or os.cpu_count() or 2
    t0 = time.monotonic()

    def progress(i, n, r):
        if i % 50 == 0 or i == n:
            sys.stderr.write("\r%d/%d scores, %.0f s" % (i, n, time.monotonic() - t0))
            sys.stderr.flush()

    results, workdir = render_check.run_many(args.ictusd, seeds, workdir=args.workdir, jobs=jobs,
                                             nuances=nuances, extra_args=args.render_args,
                                             progress=progress, kit=args.kit)
    wall = time.monotonic() - t0
    sys.stderr.write("\n")

    notes = [n for r in results for n in r.notes]
    refused = [r for r in results if r.refused]
    crashed = [r for r in results if r.crashed]
    rendered = [r for r in results if not r.refused and not r.crashed]
    bad_scores = [r for r in results if not r.ok]
    status = {}
    for n in notes:
        status[n["status"]] = status.get(n["status"], 0) + 1
    extra = [(r.seed, s) for r in results for s in r.extra]
    bounces = sum(r.bounces for r in results)
    scores_with_bounces = sum(1 for r in results if r.bounces)
    assigned = [(r.seed, n) for r in results for n in r.notes if n["strike"] is not None]
    errs = [abs(n["error_ms"]) for _, n in assigned]
    signed = [n["error_ms"] for _, n in assigned]
    worst_seed, worst_note = max(assigned, key=lambda x: abs(x[1]["error_ms"])) if assigned else (None, None)
    contacts = [n["strike"]["duration_ms"] for _, n in assigned]
    ratios = [n["strike"]["normal_velocity_mps"] / n["planned_impact_speed_mps"] for _, n in assigned
              if n.get("planned_impact_speed_mps")]
    simulated = sum(r.simulated_s for r in results)
    cpu = sum(r.render_s for r in results)
    other_problems = [(r.seed, p) for r in results for p in r.problems
                      if "notes not played right" not in p and "extra primary" not in p]
    limits = [r.joint_limits_deg for r in results if r.joint_limits_deg is not None]
    trunk = [(r.seed, p, v) for r in results for p, v in r.trunk if isinstance(v, (int, float))]

    render_args = (["--kit", args.kit] if args.kit else []) + args.render_args
    print("## Random scores: %d seeds (%d..%d), `%s`%s\n"
          % (len(results), seeds[0], seeds[-1], os.path.basename(args.ictusd),
             (" " + " ".join(render_args)) if render_args else ""))
    print("Rendered in %.0f s wall (%d jobs; %.0f s simulated, %.0f s of renders, %.1fx real time "
          "per render). Nuances: %s.\n" % (wall, jobs, simulated, cpu, simulated / max(cpu, 1e-9),
                                            ", ".join(nuances)))
    print("| what | value |")
    print("|---|---|")
    print("| scores / played right (every note, no extra) | %d / %d (%.1f %%) |"
          % (len(results), len(results) - len(bad_scores),
             100.0 * (len(results) - len(bad_scores)) / max(len(results), 1)))
    print("| scores refused by ictusd / crashed | %d / %d |" % (len(refused), len(crashed)))
    print("| notes | %d |" % len(notes))
    print("| notes right (one primary within ±%g ms) | %d (%.2f %%) |"
          % (render_check.TOLERANCE_MS, status.get("ok", 0), 100.0 * status.get("ok", 0) / max(len(notes), 1)))
    print("| missed notes (no primary within 50 ms) | %d |" % status.get("missed", 0))
    print("| off-time notes (nearest primary beyond ±%g ms) | %d |" % (render_check.TOLERANCE_MS,
                                                                     status.get("off-time", 0)))
    print("| notes with two primaries within ±%g ms | %d |" % (render_check.TOLERANCE_MS,
                                                             status.get("double", 0)))
    print("| extra primary strikes | %d (in %d scores) |" % (len(extra), len({s for s, _ in extra})))
    print("| bounces (tagged) | %d (in %d scores) |" % (bounces, scores_with_bounces))
    print("| timing error \\|strike − beat\\| mean / p50 / p99 (ms; notes with a strike within 50 ms) | %.2f / %.2f / %.2f |"
          % (mean(errs), pct(errs, 50), pct(errs, 99)))
    if worst_note:
        print("| worst timing error (ms; beyond 50 ms a note counts as missed) | %+.2f (seed %d, %s %s %s at %.0f bpm) |"
              % (worst_note["error_ms"], worst_seed, worst_note["hand"], worst_note["nuance"],
                 worst_note["label"], worst_note["tempo_bpm"]))
    print("| signed timing error mean (ms) | %+.2f |" % mean(signed))
    print("| contact duration median (p5 / p95) (ms) | %.1f (%.1f / %.1f) |"
          % (pct(contacts, 50), pct(contacts, 5), pct(contacts, 95)))
    print("| impact speed measured / planned median (p5 / p95) | %.3f (%.3f / %.3f) |"
          % (pct(ratios, 50), pct(ratios, 5), pct(ratios, 95)))
    print("| impact speed \\|measured / planned − 1\\| p50 / p99 | %.1f %% / %.1f %% |"
          % (100 * pct([abs(x - 1) for x in ratios], 50), 100 * pct([abs(x - 1) for x in ratios], 99)))
    print("| other faults (NaN, bounce tags, plan mismatch, limits) | %d |" % len(other_problems))
    if limits:
        print("| joint-limit excursion max / p99 (deg) | %.2f / %.2f |" % (max(limits), pct(limits, 99)))
    if trunk:
        vals = [v for _, _, v in trunk]
        print("| trunk (%s) median / max | %.4g / %.4g |" % (trunk[0][1].lstrip("."), pct(vals, 50), max(vals)))
    print()

    # Failures by feature: notes not right, and extra primaries counted on their nearest note.
    print("### Notes not played right, by score feature\n")
    print("A note is counted under each of its features; *extra* primary strikes under those of "
          "their hand's nearest note.\n")
    print("| feature | value | notes | not right | % | missed | off-time | extra |")
    print("|---|---|---|---|---|---|---|---|")
    for f in FEATURES + (["hand", "drum"] if args.kit else []):
        table = {}
        for n in notes:
            v = n["features"][f]
            row = table.setdefault(v, {"notes": 0, "bad": 0, "missed": 0, "off": 0, "extra": 0})
            row["notes"] += 1
            if n["status"] != "ok":
                row["bad"] += 1
            if n["status"] == "missed":
                row["missed"] += 1
            if n["status"] == "off-time":
                row["off"] += 1
        for _, s in extra:
            nn = s.get("nearest_note")
            if nn:
                v = nn["features"][f]
                table.setdefault(v, {"notes": 0, "bad": 0, "missed": 0, "off": 0, "extra": 0})["extra"] += 1
        order = ORDER.get(f)
        keys = sorted(table, key=lambda k: (order.index(k) if order and k in order else 99, str(k)))
        for k in keys:
            row = table[k]
            print("| %s | %s | %d | %d | %.1f | %d | %d | %d |"
                  % (f, k, row["notes"], row["bad"], 100.0 * row["bad"] / max(row["notes"], 1),
                     row["missed"], row["off"], row["extra"]))
    print()

    print("### Failing seeds\n")
    if not bad_scores:
        print("None.")
    else:
        worst = sorted(bad_scores, key=lambda r: -(len(r.failing_notes()) + len(r.extra)))
        print("%d scores: %s\n" % (len(bad_scores), " ".join(str(r.seed) for r in bad_scores[:200])
                                   + (" ..." if len(bad_scores) > 200 else "")))
        print("Worst ten (notes not right + extra primaries):\n")
        for r in worst[:10]:
            print("- seed %d: %s" % (r.seed, "; ".join(r.problems)))
    if other_problems:
        print("\nOther faults:\n")
        for seed, p in other_problems[:40]:
            print("- seed %d: %s" % (seed, p))
    for r in crashed[:5]:
        print("\nseed %d crashed: %s" % (r.seed, r.crashed))

    if args.json:
        def clean(n):
            return {k: v for k, v in n.items() if k not in ("strike",)} | (
                {"strike_velocity_mps": n["strike"]["normal_velocity_mps"],
                 "strike_contact_ms": n["strike"]["duration_ms"]} if n["strike"] else {})
        with open(args.json, "w") as f:
            json.dump({"seeds": seeds, "nuances": nuances,
                       "scores": [{"seed": r.seed, "ok": r.ok, "problems": r.problems,
                                   "bounces": r.bounces,
                                   "extra": [{k: v for k, v in s.items() if k != "nearest_note"}
                                             for s in r.extra],
                                   "notes": [clean(n) for n in r.notes]} for r in results]},
                      f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
