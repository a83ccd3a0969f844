#!/usr/bin/env python3
"""ictus-corpus end to end (docs/corpus.md), one part per CTest test:

  small    4 items on a LocalCluster of 2 workers: every label onset within 1 ms of the onset
           measured in its WAV (ictus_corpus.check: the WAV against renders cut before each hit,
           never reading the labels), manifest / card / splits consistent (the splits recomputed
           here from SHA-256 of (seed, index)), and a rerun renders 0 items.
  kill     SIGKILL of the whole run (its process group) as soon as the first item is in place
           (polled, with a deadline), then every item folder present is complete (its files'
           SHA-256 recomputed here against checksums.json) and the rerun completes the rest.
  cluster  a real `dask scheduler` and two `dask worker` processes on free localhost ports
           (waited for by handshake): --scheduler gives items byte-identical to a local run,
           and a local run of fewer items gives the same first items (item k does not depend
           on --count).

Needs build/venv (scripts/venv.sh): without it the test skips (77), or fails under CI=true.
"""
import argparse
import hashlib
import json
import os
import signal
import socket
import subprocess
import sys
import tempfile
import time

from ictus_tools.pdrun import free_port

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
failures = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what, flush=True)
    if not cond:
        failures.append(what)


def env():
    e = dict(os.environ)
    e["PYTHONPATH"] = os.path.join(ROOT, "python") + (
        ":" + e["PYTHONPATH"] if e.get("PYTHONPATH") else "")
    return e


def corpus(py, build, out, *args, **kw):
    cmd = [py, "-m", "ictus_corpus", "--ictusd", os.path.join(build, "ictusd"), "--out", out]
    cmd += list(args)
    return subprocess.Popen(cmd, env=env(), **kw)


def run_corpus(py, build, out, *args):
    p = corpus(py, build, out, *args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    log, _ = p.communicate(timeout=600)
    print(log[-2000:])
    with open(os.path.join(out, "last_run.json")) as f:
        return p.returncode, json.load(f)


def complete(folder):
    """checksums.json names performance.wav, labels.json ... and every file matches (computed
    here with hashlib, not by the package)."""
    try:
        with open(os.path.join(folder, "checksums.json")) as f:
            sums = json.load(f)
    except (OSError, ValueError):
        return False
    need = {"performance.wav", "performance.mid", "strikes.csv", "notes.csv", "labels.json",
            "render.json", "events.txt", "score.txt"}
    if not need <= set(sums):
        return False
    for name, digest in sums.items():
        with open(os.path.join(folder, name), "rb") as f:
            if hashlib.sha256(f.read()).hexdigest() != digest:
                return False
    return True


def items(out):
    return sorted(d for d in os.listdir(out) if d.startswith("item-"))


def part_small(py, build, work):
    out = os.path.join(work, "c")
    rc, s = run_corpus(py, build, out, "--count", "4", "--seed", "7", "--workers", "2")
    check(rc == 0 and s["rendered"] == 4 and s["failed"] == 0, "4 items rendered, 0 failed (%s)" % s)
    check(items(out) == ["item-%06d" % k for k in range(4)] and all(
        complete(os.path.join(out, d)) for d in items(out)), "4 complete item folders")
    p = subprocess.run([py, "-m", "ictus_corpus.check", out, "--build", build], env=env(),
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=600)
    print(p.stdout[-3000:])
    check(p.returncode == 0, "every label onset within 1 ms of the onset measured in its WAV")
    out_py = subprocess.run([py, "-c", "import pandas as pd, sys; df = pd.read_parquet(sys.argv[1]);"
                             "print(df[['index','status','split','sha256']].to_json(orient='records'))",
                             os.path.join(out, "manifest.parquet")], env=env(),
                            stdout=subprocess.PIPE, text=True, timeout=120)
    rows = json.loads(out_py.stdout)
    check([r["index"] for r in rows] == [0, 1, 2, 3] and all(r["status"] == "done" for r in rows),
          "manifest: one row per item, all done")
    for r in rows:
        with open(os.path.join(out, "item-%06d" % r["index"], "checksums.json")) as f:
            check(json.loads(r["sha256"]) == json.load(f), "manifest checksums of item %d" % r["index"])
        h = hashlib.sha256(("ictus-corpus-split:7:%d" % r["index"]).encode()).digest()
        u = int.from_bytes(h[:8], "big") / 2.0 ** 64
        want = "train" if u < 0.8 else "validation" if u < 0.9 else "test"
        check(r["split"] == want, "item %d split %s (SHA-256 of seed, index: %s)"
              % (r["index"], r["split"], want))
        with open(os.path.join(out, "item-%06d" % r["index"], "labels.json")) as f:
            check(json.load(f)["item"]["split"] == want, "labels.json holds the split")
    with open(os.path.join(out, "README.md")) as f:
        card_text = f.read()
    check("BSD-3-Clause" in card_text and "4 finished, 0 failed" in card_text and
          "| impact_speed_mps |" in card_text, "dataset card: licence, counts, label schema")
    rc, s = run_corpus(py, build, out, "--count", "4", "--seed", "7", "--workers", "2")
    check(rc == 0 and s["rendered"] == 0 and s["skipped"] == 4, "rerun renders 0 items (%s)" % s)


def part_kill(py, build, work):
    out = os.path.join(work, "k")
    args = ("--count", "6", "--seed", "11", "--workers", "2")
    p = corpus(py, build, out, *args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
               start_new_session=True)
    deadline = time.time() + 180
    while time.time() < deadline and p.poll() is None:
        if os.path.isdir(out) and items(out):
            break
        time.sleep(0.05)
    check(p.poll() is None and items(out), "the first item is in place while the run goes on")
    os.killpg(p.pid, signal.SIGKILL)   # the command, its Dask workers, their ictusd and pd
    p.wait(timeout=60)
    before = items(out)
    print("killed with %d of 6 item folders in place" % len(before))
    check(all(complete(os.path.join(out, d)) for d in before),
          "after SIGKILL every item folder is complete (no item without all its files)")
    check(len(before) < 6, "the kill came before the end (%d of 6)" % len(before))
    rc, s = run_corpus(py, build, out, *args)
    check(rc == 0 and s["skipped"] == len(before) and s["rendered"] == 6 - len(before),
          "the rerun renders only the missing items (%s)" % s)
    check(items(out) == ["item-%06d" % k for k in range(6)] and all(
        complete(os.path.join(out, d)) for d in items(out)), "then all 6 items are complete")


def part_cluster(py, build, work):
    bindir = os.path.dirname(py)
    port = free_port(socket.SOCK_STREAM)
    url = "tcp://127.0.0.1:%d" % port
    procs = []
    try:
        procs.append(subprocess.Popen([os.path.join(bindir, "dask"), "scheduler", "--host",
                                       "127.0.0.1", "--port", str(port), "--no-dashboard"],
                                      env=env(), stdout=subprocess.DEVNULL,
                                      stderr=subprocess.DEVNULL))
        for _ in range(2):
            procs.append(subprocess.Popen([os.path.join(bindir, "dask"), "worker", url,
                                           "--nworkers", "1", "--nthreads", "1",
                                           "--no-dashboard"], env=env(),
                                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        # handshake: a client sees both workers (its own deadline)
        w = subprocess.run([py, "-c", "from dask.distributed import Client; import sys;"
                            "c = Client(sys.argv[1], timeout=60); c.wait_for_workers(2, timeout=60);"
                            "print(len(c.scheduler_info()['workers'])); c.close()", url],
                           env=env(), stdout=subprocess.PIPE, text=True, timeout=150)
        check(w.returncode == 0 and w.stdout.strip() == "2", "scheduler with 2 workers at %s" % url)
        dist, local = os.path.join(work, "dist"), os.path.join(work, "local")
        rc, s = run_corpus(py, build, dist, "--count", "3", "--seed", "5", "--scheduler", url)
        check(rc == 0 and s["rendered"] == 3, "3 items through --scheduler (%s)" % s)
    finally:
        for p in reversed(procs):
            p.terminate()
        for p in procs:
            try:
                p.wait(timeout=30)
            except subprocess.TimeoutExpired:
                p.kill()
    rc, s = run_corpus(py, build, local, "--count", "2", "--seed", "5", "--workers", "1")
    check(rc == 0 and s["rendered"] == 2, "2 items locally (%s)" % s)
    for d in items(local):
        names = sorted(os.listdir(os.path.join(local, d)))
        same = names == sorted(os.listdir(os.path.join(dist, d))) and all(
            open(os.path.join(local, d, n), "rb").read() == open(os.path.join(dist, d, n), "rb").read()
            for n in names)
        check(same, "%s: byte-identical through the scheduler and locally (%d files)" % (d, len(names)))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    ap.add_argument("--part", choices=["small", "kill", "cluster"], required=True)
    a = ap.parse_args()
    py = os.path.join(a.build, "venv", "bin", "python")
    probe = subprocess.run([py, "-c", "import dask.distributed, pandas, pyarrow"],
                           capture_output=True) if os.path.exists(py) else None
    if probe is None or probe.returncode != 0:
        msg = "no usable %s (make it with scripts/venv.sh %s)" % (py, a.build)
        if os.environ.get("CI") == "true":
            print("FAIL " + msg)
            return 1
        print("SKIP " + msg)
        return 77
    with tempfile.TemporaryDirectory(prefix="ictus-corpus-test-") as work:
        {"small": part_small, "kill": part_kill, "cluster": part_cluster}[a.part](py, a.build, work)
    print("%d failures" % len(failures))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
