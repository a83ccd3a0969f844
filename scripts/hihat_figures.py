#!/usr/bin/env python3
"""The hi-hat measured in real pd, for docs/plates.md ("The hi-hat").

Renders membrane~ "preset hihat" struck once by contact~ (a 13.8 g stick, wood tip, at
2 m/s, on the bow at r/a 0.7, the preset's strike point) with the pedal closed
(openness 0), half open (0.5) and open (1), pickup 1, 4 s each, all in one pd run.
Prints per render the broadband T60 (Schroeder's backward integral, a line fitted from
-5 to -25 dB, extrapolated to -60 dB), the spectral centroid of 0-50 ms and 150-200 ms
and the T60 the damping law gives the lowest modes (membrane~ "print"); writes
docs/img/hihat.png (spectrograms of the three, the first 2 s).

Usage: PYTHONPATH=python scripts/hihat_figures.py --build BUILD [--out docs/img]
Needs python3-matplotlib and numpy (Debian packages)."""
import argparse
import os
import sys

import numpy as np

from ictus_tools.decay import centroid, schroeder_t60
from ictus_tools.pdrun import (Patch, make_workdir, membrane_modes_from_log, read_wav_float,
                               recorder, run_pd)

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

SR = 48000
SECONDS = 4.0
PEDAL = [("closed", 0.0), ("half", 0.5), ("open", 1.0)]
SPEED, MASS, R_OVER_A = 2.0, 0.0138, 0.7


def render(build):
    work = make_workdir("ictus-hihat-figures-")
    wav = os.path.join(work, "hihat.wav")
    p = Patch(declare="-path %s/ictus" % build)
    heads = [p.obj("membrane~ hihat-%s" % name) for name, _o in PEDAL]
    trig = recorder(p, [(h, 0, "t%d" % i) for i, h in enumerate(heads)], SECONDS, SR, wav)
    for i, (name, openness) in enumerate(PEDAL):
        setup = p.msg("preset hihat \\, openness %g \\, print" % openness)
        stick = p.obj("contact~ hihat-%s" % name)
        hit = p.msg("tip wood \\, hit %g %g 0 %g" % (SPEED, R_OVER_A, MASS))
        p.connect(trig, 1, setup, 0)
        p.connect(setup, 0, heads[i], 0)
        p.connect(trig, 1, hit, 0)
        p.connect(hit, 0, stick, 0)
    rc, log = run_pd(p.text(), build, sr=SR, workdir=work, timeout=600)
    if rc != 0:
        sys.exit("pd failed:\n" + log)
    x, _ = read_wav_float(wav)
    return x, log


def figure(x, t60s, path):
    fig, axes = plt.subplots(1, 3, figsize=(10, 3.2), dpi=72, sharey=True)
    for i, (ax, (name, openness)) in enumerate(zip(axes, PEDAL)):
        # a floor far below the colour scale: a closed hat decays to exact zeros, whose
        # log would be drawn blank
        with np.errstate(divide="ignore"):
            ax.specgram(x[:2 * SR, i] + 1e-12, NFFT=1024, Fs=SR, noverlap=896, cmap="magma",
                        vmin=-170, vmax=-50)
        ax.set_ylim(0, 20000)
        ax.set_xlabel("time, s")
        ax.set_title("hihat %s (openness %g): T60 %.2f s" % (name, openness, t60s[i]),
                     fontsize=9)
    axes[0].set_ylabel("frequency, Hz")
    fig.suptitle("scripts/hihat_figures.py: 13.8 g wood tip at 2 m/s, r/a 0.7, pickup 1, "
                 "real pd", fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    ap.add_argument("--out", default=os.path.join(os.path.dirname(__file__), "..", "docs", "img"))
    args = ap.parse_args()
    x, log = render(os.path.abspath(args.build))
    if not np.all(np.isfinite(x)):
        sys.exit("output not finite")
    modes = membrane_modes_from_log(log, "hihat-")
    t60s = [schroeder_t60(x[:, i], SR) for i in range(len(PEDAL))]
    print("| pedal | openness | T60, measured | centroid 0-50 ms | centroid 150-200 ms "
          "| lowest modes: f, T60 (law) |")
    print("|---|---|---|---|---|---|")
    for i, (name, openness) in enumerate(PEDAL):
        y = x[:, i]
        ml = ", ".join("%s %.0f Hz %.2f s" % m for m in modes.get(name, [])[:3])
        print("| %s | %g | %.3f s | %.0f Hz | %.0f Hz | %s |" % (
            name, openness, t60s[i], centroid(y, SR, 0, 0.05), centroid(y, SR, 0.15, 0.2), ml))
    os.makedirs(args.out, exist_ok=True)
    figure(x, t60s, os.path.join(args.out, "hihat.png"))


if __name__ == "__main__":
    main()
