"""ictus-corpus: labelled drum performances rendered by ictusd on Dask (docs/corpus.md).

    python3 -m ictus_corpus --count N --seed S --out DIR [--workers N] [--scheduler URL]
                            [--from DIR] [--bvh] [--ictusd PATH]
"""
import argparse
import json
import os
import sys
import time

from ictus_corpus import card, item, params as P

MANIFEST = "manifest.parquet"


def find_ictusd(given):
    if given:
        return os.path.abspath(given)
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    return os.path.join(root, "build", "ictusd")


def plan(args):
    """[(params, score_text, source, length_s)] of every item, in index order (length_s: the
    score's length, 0 where it is not known before the render)."""
    if args.from_dir:
        files = sorted(f for f in os.listdir(args.from_dir)
                       if f.lower().endswith((".txt", ".score", ".mid", ".midi")))
        if not files:
            raise SystemExit("ictus-corpus: --from %s: no score (.txt) or MIDI (.mid) file"
                             % args.from_dir)
        count = args.count if args.count else len(files)
        out = []
        for k in range(count):
            src = os.path.abspath(os.path.join(args.from_dir, files[k % len(files)]))
            out.append((P.from_file(args.seed, k, src), None, src, 0.0))
        return out
    out = []
    for k in range(args.count):
        prm, text, length_s = P.draw(args.seed, k)
        out.append((prm, text, None, length_s))
    return out


def _task(ictusd, out, prm, text, src, bvh):
    # the item's own module is imported on the worker (PYTHONPATH carries python/)
    from ictus_corpus.item import render_item
    return render_item(ictusd, out, prm, text, src, bvh)


def make_client(args):
    from dask.distributed import Client, LocalCluster
    if args.scheduler:
        return Client(args.scheduler), None
    import dask
    # a worker that dies while rendering costs its task one failure; the second is final
    dask.config.set({"distributed.scheduler.allowed-failures": 1})
    n = args.workers or os.cpu_count() or 1
    cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                           dashboard_address=":0" if args.dashboard else None)
    return Client(cluster), cluster


def run(args):
    out = os.path.abspath(args.out)
    os.makedirs(os.path.join(out, ".tmp"), exist_ok=True)
    ictusd = find_ictusd(args.ictusd)
    if not os.access(ictusd, os.X_OK):
        raise SystemExit("ictus-corpus: no ictusd at %s (--ictusd PATH, or build it)" % ictusd)
    items = plan(args)
    # already finished: checked here, so that they cost no task
    rows, todo = [], []
    for prm, text, src, length_s in items:
        folder = os.path.join(out, item.item_name(prm["index"]))
        sums = item.is_done(folder, args.bvh)
        if sums is not None:
            r = dict(prm, status="skipped", error="", files=sorted(sums),
                     sha256=json.dumps(sums, sort_keys=True), render_s=0.0, host="")
            rows.append(r)
        else:
            todo.append((prm, text, src, length_s))
    print("ictus-corpus: %d items, %d finished already, %d to render into %s"
          % (len(items), len(rows), len(todo), out), flush=True)
    t0 = time.time()
    if todo:
        from dask.distributed import as_completed
        client, cluster = make_client(args)
        try:
            if cluster is not None:
                # the rate counts rendering, not the local workers' start-up
                client.wait_for_workers(len(cluster.workers), timeout=120)
                t0 = time.time()
            if client.dashboard_link and args.dashboard:
                print("ictus-corpus: Dask dashboard at %s" % client.dashboard_link, flush=True)
            # the longest scores first (Dask runs higher priorities first): the last
            # items to finish are short ones, so no worker idles long at the end
            futures = [client.submit(_task, ictusd, out, prm, text, src, args.bvh,
                                     key="ictus-item-%d-%d" % (args.seed, prm["index"]),
                                     retries=1, pure=False, priority=int(length_s * 1000))
                       for prm, text, src, length_s in todo]
            bar = _bar(len(todo))
            for fut in as_completed(futures):
                try:
                    r = fut.result()
                except Exception as e:  # the worker died twice: recorded, the run goes on
                    k = futures.index(fut)
                    r = dict(todo[k][0], status="failed", files=[], sha256="", render_s=0.0,
                             host="", error="%s: %s" % (type(e).__name__, e))
                rows.append(r)
                bar.update(1)
                if r["status"] == "failed":
                    bar.write("ictus-corpus: item %d failed: %s" % (r["index"], r["error"]))
            bar.close()
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    wall = time.time() - t0
    rows.sort(key=lambda r: r["index"])
    write_manifest(out, rows)
    card.write(out, args, rows, ictusd)
    rendered = sum(r["status"] == "done" for r in rows)
    failed = sum(r["status"] == "failed" for r in rows)
    rate = rendered / wall * 60 if rendered and wall > 0 else 0.0
    print("ictus-corpus: rendered %d, skipped %d, failed %d in %.1f s (%.1f items/min); "
          "manifest %s" % (rendered, len(rows) - rendered - failed, failed, wall, rate,
                           os.path.join(out, MANIFEST)), flush=True)
    summary = {"rendered": rendered, "failed": failed, "skipped": len(rows) - rendered - failed,
               "wall_s": wall}
    with open(os.path.join(out, "last_run.json"), "w") as f:
        json.dump(summary, f, indent=1)
    return 1 if failed else 0


def _bar(total):
    try:
        from tqdm import tqdm
        return tqdm(total=total, unit="item", desc="ictus-corpus", file=sys.stderr)
    except ImportError:  # a plain counter
        class Plain:
            n = 0

            def update(self, k):
                self.n += k
                print("ictus-corpus: %d/%d" % (self.n, total), file=sys.stderr, flush=True)

            def write(self, s):
                print(s, file=sys.stderr, flush=True)

            def close(self):
                pass
        return Plain()


def write_manifest(out, rows):
    """manifest.parquet: one row per item (parameters, files, sha256 as JSON, status, error),
    written to a temporary file and renamed."""
    import pandas as pd
    df = pd.DataFrame(rows)
    df["files"] = df["files"].apply(lambda f: ",".join(f))
    tmp = os.path.join(out, ".tmp", MANIFEST)
    df.to_parquet(tmp, index=False)
    os.replace(tmp, os.path.join(out, MANIFEST))


def main(argv=None):
    ap = argparse.ArgumentParser(prog="ictus-corpus", description=__doc__.split("\n")[0])
    ap.add_argument("--count", type=int, default=0, help="items (with --from: default one per file)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", required=True)
    ap.add_argument("--workers", type=int, default=0, help="local worker processes (default: cores)")
    ap.add_argument("--scheduler", default="", help="tcp://HOST:PORT of a running Dask scheduler")
    ap.add_argument("--from", dest="from_dir", default="", help="a folder of scores / MIDI files")
    ap.add_argument("--bvh", action="store_true", help="write performance.bvh too (250 Hz)")
    ap.add_argument("--dashboard", action="store_true", help="local cluster: serve the dashboard")
    ap.add_argument("--ictusd", default="", help="the ictusd binary (default build/ictusd)")
    args = ap.parse_args(argv)
    if args.count < 0 or (args.count == 0 and not args.from_dir):
        ap.error("--count must be a positive number of items")
    if args.workers < 0:
        ap.error("--workers must be >= 0")
    return run(args)
