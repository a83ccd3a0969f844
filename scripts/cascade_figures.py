#!/usr/bin/env python3
"""The energy cascade measured in real pd: the crash's for docs/plates.md ("The cascade"), a
drum head's for docs/sound.md ("Expression", `--preset tom`).

Renders membrane~ "preset crash" struck once by contact~ (a 13.8 g stick, wood tip, at
r/a 0.9, as docs/plates.md's linear measurement) at several speeds, with the preset's
energy cascade (cascade 3) and without it (cascade 0), pickup 1, 1.5 s each, all in one
pd run. Prints per render the spectral centroid of 0-50 ms and 150-200 ms, the share of
energy above 5 kHz in 0-50 ms, 0-200 ms and 0-1 s, and the share of the render's energy
that the cascade moved (|on - off|^2 / off^2 over 0-1 s); writes
docs/img/plate-cascade.png (spectrograms of the ff stroke, 6 m/s, on and off).

Spectra: 1024-sample Hann frames hopped by 256 over the window (each sample weighs the
same). Usage: PYTHONPATH=python scripts/cascade_figures.py --build BUILD [--out docs/img]
       [--amounts 3,0] [--speeds 0.5,2,6,12,20] [--preset crash] [--ra 0.9] [--tip wood]
       [--stretch K3] [--ff 6] [--fmax 16000]
The tom as docs/sound.md measures it: --preset tom --amounts 1,0 --speeds 0.25,2,4,5.92
--ra 0.33 --tip default --stretch 5.27e7 --ff 5.92 --fmax 4000 (docs/img/tom-cascade.png).
Needs python3-matplotlib and numpy (Debian packages)."""
import argparse
import os
import sys

import numpy as np

from ictus_tools.pdrun import Patch, make_workdir, read_wav_float, recorder, run_pd

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

SR = 48000
SECONDS = 1.5
SPEEDS = [0.5, 2.0, 6.0, 12.0, 20.0]
FF = 6.0  # m/s: ff (docs/gestures.md)
MASS = 0.0138
R_OVER_A = 0.9


def render(build, speeds=SPEEDS, amounts=(3, 0), preset="crash", ra=R_OVER_A, tip="wood",
           stretch=None):
    work = make_workdir("ictus-cascade-")
    wav = os.path.join(work, "cascade.wav")
    p = Patch(declare="-path %s/ictus" % build)
    runs = [(v, c) for v in speeds for c in amounts]
    heads = [p.obj("membrane~ crash%d" % i) for i in range(len(runs))]
    trig = recorder(p, [(h, 0, "t%d" % i) for i, h in enumerate(heads)], SECONDS, SR, wav)
    for i, (v, c) in enumerate(runs):
        setup = p.msg("preset %s \\, cascade %g" % (preset, c))
        stick = p.obj("contact~ crash%d" % i)
        tip = p.msg(("tip %s" % tip if tip != "default" else "mass %g" % MASS)
                    + ("" if stretch is None else " \\, stretch %g" % stretch))
        hit = p.msg("hit %g %g 0 %g" % (v, ra, MASS))
        p.connect(trig, 1, setup, 0)
        p.connect(setup, 0, heads[i], 0)
        p.connect(trig, 1, tip, 0)
        p.connect(tip, 0, stick, 0)
        p.connect(trig, 1, hit, 0)
        p.connect(hit, 0, stick, 0)
    rc, log = run_pd(p.text(), build, sr=SR, workdir=work, timeout=900)
    if rc != 0:
        sys.exit("pd failed:\n" + log)
    x, _ = read_wav_float(wav)
    return runs, x


def spectrum(y, t0, t1, n=1024, hop=256):
    """Power over t0..t1 from Hann frames of n hopped by n / 4, whose squares sum to a
    constant: every sample of the window weighs the same (the attack included)."""
    seg = np.concatenate([np.zeros(n), y[int(t0 * SR):int(t1 * SR)].astype(np.float64),
                          np.zeros(n)])
    w = np.hanning(n)
    power = np.zeros(n // 2 + 1)
    for s in range(0, len(seg) - n + 1, hop):
        power += np.abs(np.fft.rfft(seg[s:s + n] * w)) ** 2
    return np.fft.rfftfreq(n, 1.0 / SR), power


def centroid(y, t0, t1):
    f, pw = spectrum(y, t0, t1)
    return np.sum(f * pw) / np.sum(pw)


def above(y, t0, t1, hz=5000.0):
    f, pw = spectrum(y, t0, t1)
    return np.sum(pw[f > hz]) / np.sum(pw)


def figure(on, off, speed, path, preset, amounts, fmax, tip):
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.2), dpi=72)
    labels = ("cascade %g" % amounts[0], "cascade %g (off)" % amounts[-1])
    for ax, y, label in ((axes[0], on, labels[0]), (axes[1], off, labels[1])):
        y = y[:SR]
        ax.specgram(y, NFFT=1024, Fs=SR, noverlap=896, cmap="magma", vmin=-170, vmax=-50)
        ax.set_ylim(0, fmax)
        ax.set_xlabel("time, s")
        ax.set_title("%s, %s: 13.8 g %s tip at %g m/s" % (preset, label, tip, speed), fontsize=9)
    axes[0].set_ylabel("frequency, Hz")
    t = np.arange(0.0, 0.5, 0.025)
    for y, label in ((on, labels[0] + " (the preset's)"), (off, labels[1])):
        axes[2].plot(t + 0.0125, [centroid(y, a, a + 0.025) for a in t], label=label)
    axes[2].set_xlabel("time, s")
    axes[2].set_ylabel("spectral centroid, Hz (25 ms windows)")
    axes[2].legend(fontsize=8)
    fig.suptitle("scripts/cascade_figures.py (pickup 1, real pd)", fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    ap.add_argument("--out", default=os.path.join(os.path.dirname(__file__), "..", "docs", "img"))
    ap.add_argument("--amounts", default="3,0", help="cascade values, the last one the reference")
    ap.add_argument("--speeds", default=",".join("%g" % v for v in SPEEDS))
    ap.add_argument("--preset", default="crash")
    ap.add_argument("--ra", type=float, default=R_OVER_A)
    ap.add_argument("--tip", default="wood", help="contact~'s tip, or 'default' (its own)")
    ap.add_argument("--stretch", type=float, default=None, help="contact~'s head stretching k3")
    ap.add_argument("--ff", type=float, default=FF, help="the speed the figure shows")
    ap.add_argument("--fmax", type=float, default=16000.0)
    ap.add_argument("--no-figure", action="store_true")
    args = ap.parse_args()
    amounts = [float(a) for a in args.amounts.split(",")]
    speeds = [float(v) for v in args.speeds.split(",")]
    runs, x = render(os.path.abspath(args.build), speeds, amounts, args.preset, args.ra, args.tip,
                     args.stretch)
    print("| speed | cascade | centroid 0-50 ms | centroid 150-200 ms | > 5 kHz, 0-50 ms "
          "| > 5 kHz, 0-200 ms | > 5 kHz, 0-1 s | moved by the cascade |")
    print("|---|---|---|---|---|---|---|---|")
    per = len(amounts)
    for i, (v, c) in enumerate(runs):
        y = x[:, i]
        off = x[:, (i // per) * per + per - 1]
        moved = np.sum((y[:SR] - off[:SR]) ** 2) / np.sum(off[:SR] ** 2)
        print("| %g m/s | %g | %.0f Hz | %.0f Hz | %.1f %% | %.1f %% | %.1f %% | %s |" % (
            v, c, centroid(y, 0, 0.05), centroid(y, 0.15, 0.2), 100 * above(y, 0, 0.05),
            100 * above(y, 0, 0.2), 100 * above(y, 0, 1.0), "%.2g" % moved if c != amounts[-1]
            else "-"))
    if args.no_figure or args.ff not in speeds:
        return
    os.makedirs(args.out, exist_ok=True)
    i = speeds.index(args.ff) * per
    name = "plate-cascade.png" if args.preset == "crash" else "%s-cascade.png" % args.preset
    figure(x[:, i], x[:, i + per - 1], args.ff, os.path.join(args.out, name), args.preset,
           amounts, args.fmax, args.tip)


if __name__ == "__main__":
    main()
