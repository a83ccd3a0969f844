#!/usr/bin/env python3
"""ictus-corpus throughput: items per minute with 1 and with 2 local Dask workers, in the same
run, on the same items, and their ratio (docs/benchmarks.md, "ictus-corpus"; target >= 1.7).

    PYTHONPATH=python build/venv/bin/python bench/corpus_scaling.py [--count 32] [--seed 3]
                                                                   [--rounds 2]

Each pass renders the same --count items (seed --seed) into a fresh folder with
`python -m ictus_corpus --workers W`; the rate is the command's own (rendered items over the
wall time from the first submitted task to the last result: the cluster's start-up and the
manifest are outside it, and printed beside it as the whole command's time). The passes
alternate, 1 then 2 workers, --rounds times, and each rate is its best round: this machine's
speed drifts between passes (other guests), and alternating exposes both to the same drift."""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def one(workers, count, seed, work):
    out = os.path.join(work, "w%d" % workers)
    shutil.rmtree(out, ignore_errors=True)
    env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "python"))
    t0 = time.time()
    subprocess.run([sys.executable, "-m", "ictus_corpus", "--count", str(count), "--seed",
                    str(seed), "--out", out, "--workers", str(workers)], env=env, check=True,
                   stderr=subprocess.DEVNULL)
    whole = time.time() - t0
    with open(os.path.join(out, "last_run.json")) as f:
        s = json.load(f)
    if s["rendered"] != count:
        raise SystemExit("%d workers: %d of %d items rendered" % (workers, s["rendered"], count))
    return count / s["wall_s"] * 60.0, whole


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--count", type=int, default=32)
    ap.add_argument("--seed", type=int, default=3)
    ap.add_argument("--rounds", type=int, default=2)
    a = ap.parse_args()
    best = {1: (0.0, 0.0), 2: (0.0, 0.0)}
    with tempfile.TemporaryDirectory(prefix="ictus-corpus-bench-") as work:
        for _ in range(max(1, a.rounds)):
            for w in (1, 2):
                rate, whole = one(w, a.count, a.seed, work)
                print("  %d worker%s: %.1f items/min" % (w, "s" if w > 1 else "", rate), flush=True)
                best[w] = max(best[w], (rate, whole))
    (r1, w1), (r2, w2) = best[1], best[2]
    print("%d items, seed %d, %d cores, best of %d rounds" % (a.count, a.seed, os.cpu_count(),
                                                           max(1, a.rounds)))
    print("1 worker : %.1f items/min (command %.1f s)" % (r1, w1))
    print("2 workers: %.1f items/min (command %.1f s)" % (r2, w2))
    print("ratio    : %.2f (target >= 1.7)" % (r2 / r1))


if __name__ == "__main__":
    main()
