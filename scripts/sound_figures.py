#!/usr/bin/env python3
"""The presets' spectrograms and decay figures for docs/sound.md, from real renders.

Renders each drum preset in the real pd binary (membrane~ "preset NAME", one stroke of
a 50 g stick at 2.5 m/s through contact~ at the preset's strike point; the snare with
its wires on and off), writes docs/img/sound-NAME.png (spectrogram of pickup 1, the
first 1.5 s) and prints, per preset, the 95 % bandwidth of the first 50 ms, the
broadband T60 measured from the render (Schroeder backward integral, a line fitted from
-5 to -25 dB and extrapolated to -60 dB) and the first modes' frequencies and T60 the
membrane's damping law gives (membrane~ "print").

Usage: PYTHONPATH=python scripts/sound_figures.py --build BUILD [--out docs/img]
Needs python3-matplotlib and numpy (Debian packages)."""
import argparse
import os
import sys

import numpy as np

from ictus_tools.pdrun import (Patch, make_workdir, membrane_modes_from_log, read_wav_float,
                               recorder, run_pd)

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

SR = 48000
SECONDS = 1.5
# name, membrane~ messages after the preset, strike r/a (the preset's)
RENDERS = [
    ("paper", "", 0.3),
    ("snare", "", 0.3),
    ("snare-wires-off", "wires off", 0.3),
    ("tom", "", 0.3),
    ("floor-tom", "", 0.3),
    ("timpani", "", 0.75),
    ("frame", "", 0.5),
    ("kick", "", 0.15),
]


def render(build):
    work = make_workdir("ictus-figures-")
    wav = os.path.join(work, "presets.wav")
    p = Patch(declare="-path %s/ictus" % build)
    heads = []
    for i, (name, extra, _r) in enumerate(RENDERS):
        heads.append(p.obj("membrane~ %s" % name))
    trig = recorder(p, [(h, 0, "t%d" % i) for i, h in enumerate(heads)], SECONDS, SR, wav)
    for i, (name, extra, r) in enumerate(RENDERS):
        preset = name.replace("-wires-off", "")
        setup = p.msg("preset %s%s \\, print" % (preset, (" \\, " + extra) if extra else ""))
        stick = p.obj("contact~ %s" % name)
        hit = p.msg("hit 2.5 %g 0 0.05" % r)
        p.connect(trig, 1, setup, 0)
        p.connect(setup, 0, heads[i], 0)
        p.connect(trig, 1, hit, 0)
        p.connect(hit, 0, stick, 0)
    rc, log = run_pd(p.text(), build, sr=SR, workdir=work, timeout=600)
    if rc != 0:
        sys.exit("pd failed:\n" + log)
    x, _ = read_wav_float(wav)
    return x, log


def bandwidth95(y):
    nz = np.flatnonzero(np.abs(y) > 0)
    seg = y[nz[0]:nz[0] + int(0.05 * SR)].astype(np.float64)
    power = np.abs(np.fft.rfft(seg)) ** 2
    cum = np.cumsum(power) / np.sum(power)
    return np.fft.rfftfreq(len(seg), 1.0 / SR)[np.searchsorted(cum, 0.95)]


def t60_broadband(y):
    e = np.cumsum((y.astype(np.float64) ** 2)[::-1])[::-1]
    db = 10.0 * np.log10(e / e[0] + 1e-300)
    i5, i25 = np.searchsorted(-db, 5.0), np.searchsorted(-db, 25.0)
    t = np.arange(len(y)) / SR
    slope = np.polyfit(t[i5:i25], db[i5:i25], 1)[0]
    return -60.0 / slope


def spectrogram(y, name, path):
    fig, ax = plt.subplots(figsize=(7, 3.2), dpi=100)
    ax.specgram(y, NFFT=1024, Fs=SR, noverlap=896, cmap="magma", vmin=-160, vmax=-40)
    ax.set_ylim(0, 12000)
    ax.set_xlabel("time, s")
    ax.set_ylabel("frequency, Hz")
    ax.set_title("%s: 50 g stick at 2.5 m/s, pickup 1 (scripts/sound_figures.py)" % name, fontsize=9)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    ap.add_argument("--out", default=os.path.join(os.path.dirname(__file__), "..", "docs", "img"))
    args = ap.parse_args()
    build = os.path.abspath(args.build)
    os.makedirs(args.out, exist_ok=True)
    x, log = render(build)
    modes = membrane_modes_from_log(log)
    print("| render | 95 % bandwidth, first 50 ms | broadband T60 (measured) | modes: f, T60 (law) |")
    print("|---|---|---|---|")
    for i, (name, _e, _r) in enumerate(RENDERS):
        y = x[:, i]
        if not np.all(np.isfinite(y)):
            sys.exit("%s: output not finite" % name)
        spectrogram(y, name, os.path.join(args.out, "sound-%s.png" % name))
        ml = ", ".join("%s %.0f Hz %.2f s" % m for m in modes.get(name, [])[:5])
        print("| `%s` | %.0f Hz | %.2f s | %s |" % (name, bandwidth95(y), t60_broadband(y), ml))


if __name__ == "__main__":
    main()
