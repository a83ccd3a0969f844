"""Checks a corpus: every label onset against the onset measured in the item's own WAV.

    python3 -m ictus_corpus.check DIR [--build build] [--items K] [--tolerance-ms 1]

The measurement does not read the labels (ictus_tools.e2e_util, "departure onsets"): Pd is
deterministic, so the item's WAV and a render of its events.txt cut just before hit k (the drum
of render.json sent as `ictusd render --wav` sends it) are the same until hit k sounds. Hit k's
onset is the first sample where they differ by more than the WAV's quantization (the item is
24-bit PCM, the cut a float render: 1.5 LSB of 24 bits). Each label's `sample` must be within the
tolerance of it; a label with no measured onset, or an onset nobody labelled, fails. Also checked:
the files against checksums.json, and the manifest (one row per folder, statuses, splits)."""
import argparse
import json
import os
import sys
import tempfile

import numpy as np

from ictus_corpus import item as I
from ictus_tools import ROOT
from ictus_tools import e2e_util as u
from ictus_tools.pdrun import read_wav_any

LSB24 = 2.0 ** -23


def read_hits(path):
    """events.txt -> [(time_us, words)] of its hit lines, in file order. A delay may be
    negative: two strikes microseconds apart can be logged out of time order (an `R+L`)."""
    with open(path) as f:
        text = f.read()
    t, hits = 0, []
    for raw in text.split(";"):
        words = raw.split()
        if not words:
            continue
        t += int(round(float(words[0]) * 1000.0))
        if words[1:2] == ["hit"]:
            hits.append((t, words[1:]))
    return hits


def write_hits(path, hits):
    """An events file of these hits (any order), in time order, delays from their times."""
    out, prev = [], 0
    for t, words in sorted(hits, key=lambda h: h[0]):
        d = t - prev
        out.append("%d.%03d %s;" % (d // 1000, d % 1000, " ".join(words)))
        prev = t
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def measured_onsets(build, folder, work):
    """[sample of hit k's onset in folder/performance.wav or None] for every hit of events.txt
    (hit k: the hits before it in time, ties by file order, are in the cut)."""
    x, sr = read_wav_any(os.path.join(folder, "performance.wav"))[:2]
    hits = read_hits(os.path.join(folder, "events.txt"))
    header = u.drum_lines(os.path.join(folder, "render.json"))
    out = []
    for k, (tk, _) in enumerate(hits):
        ev = os.path.join(work, "prefix-%d.txt" % k)
        wav = os.path.join(work, "prefix-%d.wav" % k)
        write_hits(ev, [h for j, h in enumerate(hits) if (h[0], j) < (tk, k)])
        y, _, _ = u.render_pd(build, ev, wav, round(tk / 1e6 + 0.005, 3), sr, sends=header)
        n = min(len(x), len(y))
        diff = np.flatnonzero(np.any(np.abs(x[:n] - y[:n]) > 1.5 * LSB24, axis=1))
        out.append(int(diff[0]) if diff.size else None)
    return out, sr


def check_item(build, folder, tol_ms):
    """-> (errors_ms per label, failures [text])."""
    with open(os.path.join(folder, I.LABELS)) as f:
        lab = json.load(f)
    failures = []
    if I.is_done(folder, os.path.exists(os.path.join(folder, "performance.bvh"))) is None:
        failures.append("checksums do not match the files")
    with tempfile.TemporaryDirectory(prefix="ictus-corpus-check-") as work:
        onsets, sr = measured_onsets(build, folder, work)
    labels = sorted(lab["onsets"], key=lambda o: o["seq"])   # hit k of events.txt is strike k
    if len(onsets) != len(labels):
        failures.append("%d hits in events.txt, %d labels" % (len(onsets), len(labels)))
    errors = []
    for k, (o, l) in enumerate(zip(onsets, labels)):
        if o is None:
            failures.append("label %d (%.6f s): nothing starts in the WAV" % (k, l["time_s"]))
            errors.append(None)
            continue
        e = (o - l["sample"]) * 1000.0 / sr
        errors.append(e)
        if abs(e) > tol_ms:
            failures.append("label %d (%.6f s, %s): WAV onset %+.3f ms away"
                            % (k, l["time_s"], "bounce" if l["bounce"] else "stroke", e))
    return errors, failures


def check_manifest(out):
    import pandas as pd
    df = pd.read_parquet(os.path.join(out, "manifest.parquet"))
    folders = sorted(d for d in os.listdir(out) if d.startswith("item-"))
    fails = []
    done = df[df.status != "failed"]
    if sorted(I.item_name(i) for i in done["index"]) != folders:
        fails.append("manifest's finished items are not the item folders")
    if not set(df["split"]) <= {"train", "validation", "test"}:
        fails.append("unknown split names %s" % sorted(set(df["split"])))
    if not os.path.isfile(os.path.join(out, "README.md")):
        fails.append("no dataset card README.md")
    return df, fails


def main(argv=None):
    ap = argparse.ArgumentParser(prog="ictus_corpus.check")
    ap.add_argument("out")
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--items", type=int, default=0, help="check the first K items only (0: all)")
    ap.add_argument("--tolerance-ms", type=float, default=1.0)
    ap.add_argument("--shard", default="0/1", help="I/N: check items I, I+N, I+2N ... only")
    args = ap.parse_args(argv)
    shard, shards = (int(v) for v in args.shard.split("/"))
    df, fails = check_manifest(args.out)
    for f in fails:
        print("FAIL manifest:", f)
    folders = sorted(d for d in os.listdir(args.out) if d.startswith("item-"))
    if args.items:
        folders = folders[:args.items]
    folders = folders[shard::shards]
    all_err, bad = [], len(fails)
    for name in folders:
        errors, failures = check_item(args.build, os.path.join(args.out, name), args.tolerance_ms)
        known = [abs(e) for e in errors if e is not None]
        all_err += known
        print("%s: %d labels, max |onset - label| %.4f ms%s" % (
            name, len(errors), max(known) if known else float("nan"),
            "" if not failures else "  FAIL: " + "; ".join(failures)), flush=True)
        bad += bool(failures)
    print("checked %d items, %d labels: max %.4f ms, exact %d; %d failing" % (
        len(folders), len(all_err), max(all_err) if all_err else float("nan"),
        sum(e == 0 for e in all_err), bad))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
