#!/usr/bin/env python3
"""The snare as the performer plays it: `ictusd render --drum-preset snare` of one typed
score (pp, mf, ff, legato and accent, one note every 2 s), and per strike the 95 %
bandwidth of the first 50 ms and its share above 4 kHz, for each pickup and for both
together (the WAV's energy), and the spectral centroid of the same 50 ms (Hann window, both
pickups' power), measured in the WAV (pickups, -20 dB, 32-bit float: no
limiter). docs/sound.md, "The snare", records the figures.

Usage: PYTHONPATH=python scripts/snare_render.py --build BUILD
Needs numpy (Debian package)."""
import argparse
import csv
import os
import subprocess
import sys

import numpy as np

from ictus_tools.pdrun import make_workdir, read_wav_any

NOTES = ["legato pp", "legato mf", "legato mf", "accent mf", "legato ff"]


def band(power, f):
    cum = np.cumsum(power) / np.sum(power)
    return f[np.searchsorted(cum, 0.95)], 100.0 * np.sum(power[f > 4000.0]) / np.sum(power)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", required=True)
    args = ap.parse_args()
    work = make_workdir("ictus-snare-render-")
    score = os.path.join(work, "snare.score")
    with open(score, "w") as f:
        f.write("tempo 30\n")
        f.writelines("R %s\n" % n for n in NOTES)
    out = os.path.join(work, "out")
    wav = os.path.join(out, "p.wav")
    cmd = [os.path.join(os.path.abspath(args.build), "ictusd"), "render", "--score", score, "--out", out,
           "--drum-preset", "snare", "--wav", wav, "--wav-mix", "pickups", "--wav-gain", "-20",
           "--wav-bits", "32", "--bvh-rate", "0", "--tips-rate", "0", "--progress-every", "0"]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=900)
    if proc.returncode != 0:
        sys.exit("ictusd render failed:\n" + proc.stderr[-3000:])
    x, sr, _, _ = read_wav_any(wav)
    with open(os.path.join(out, "notes.csv")) as f:
        notes = list(csv.DictReader(f))
    with open(os.path.join(out, "strikes.csv")) as f:
        strikes = {r["seq"]: r for r in csv.DictReader(f)}
    print("| note | speed, m/s | pickup 1 | pickup 2 | both | centroid |")
    print("|---|---|---|---|---|---|")
    for word, note in zip(NOTES, notes):
        s = strikes.get(note.get("strike_seq", ""))
        if s is None:
            print("| %s | no strike | | | |" % word)
            continue
        i = int(round(float(s["time_s"]) * sr))
        seg = x[i:i + int(round(0.05 * sr))].astype(np.float64)
        power = np.abs(np.fft.rfft(seg, axis=0)) ** 2
        f = np.fft.rfftfreq(len(seg), 1.0 / sr)
        cells = [band(p, f) for p in (power[:, 0], power[:, 1], power.sum(axis=1))]
        hann = np.abs(np.fft.rfft(seg * np.hanning(len(seg))[:, None], axis=0)) ** 2
        both = hann.sum(axis=1)
        print("| %s | %.2f | %s | %.0f Hz |" % (word, float(s["normal_velocity_mps"]),
                                                " | ".join("%d Hz, %.1f %%" % c for c in cells),
                                                np.sum(both * f) / np.sum(both)))


if __name__ == "__main__":
    main()
