#!/usr/bin/env python3
"""ictus-corpus throughput: items per minute with 1 and with 2 local Dask workers, in the same
run, on the same items, and their ratio (docs/benchmarks.md, "ictus-corpus"; target >= 1.7).

    PYTHONPATH=python build/venv/bin/python bench/corpus_scaling.py [--count 16] [--seed 3]

Each pass renders the same --count items (seed --seed) into a fresh folder with
`python -m ictus_corpus --workers W`; the rate is the command's own (rendered items over the
wall time from the first submitted task to the last result: the cluster's start-up and the
manifest are outside it, and printed beside it as the whole command's time)."""
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
    ap.add_argument("--count", type=int, default=16)
    ap.add_argument("--seed", type=int, default=3)
    a = ap.parse_args()
    with tempfile.TemporaryDirectory(prefix="ictus-corpus-bench-") as work:
        r1, w1 = one(1, a.count, a.seed, work)
        r2, w2 = one(2, a.count, a.seed, work)
    print("%d items, seed %d, %d cores" % (a.count, a.seed, os.cpu_count()))
    print("1 worker : %.1f items/min (command %.1f s)" % (r1, w1))
    print("2 workers: %.1f items/min (command %.1f s)" % (r2, w2))
    print("ratio    : %.2f (target >= 1.7)" % (r2 / r1))


if __name__ == "__main__":
    main()
