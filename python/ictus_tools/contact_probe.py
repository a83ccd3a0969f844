"""One stick on one drum at a fixed point, at several speeds: what the contact does
to the sound (docs/sound.md, "Expression"; docs/contact.md).

  usage: python3 -m ictus_tools.contact_probe --build BUILD [--preset tom]
             [--mass 0.0138] [--ra 0.33] [--stretch K3] [--speeds 0.46,1.58,...]

Renders one hit per speed, 2 s apart (the drum rings out in between), through the real
pd and patches/ictus-render.pd (pickups mix, 32-bit float, -40 dB: far below its soft
limiter), on membrane~'s
preset with `contact~` given the stick mass and the head's stretching k3 (default: the
Begley & Mackin k3 of the preset's Mylar film, docs/contact.md; 0: a linear head), and
prints per hit: contact~'s duration, peak force and rebound speed (render-reports), the RMS of the
first 100 ms, the spectral centroid of the first 50 ms (Hann window, the two pickups'
power summed, as tests/e2e/test_expression.py) and the share of that energy in the
bands of the (0,1) and (1,1) modes (split halfway between the ideal membrane's f01,
f11 and f21 with the air's mass, ictus_tools.drumtone.mode_hz, from the preset's radius,
tension, density and airmass as the --drum messages leave them).
"""
import argparse
import math
import os
import subprocess
import tempfile

import numpy as np

from ictus_tools import ROOT
from ictus_tools.pdrun import PD_BATCH, PD_ENV, error_lines, read_wav_any
from ictus_tools.drumtone import mode_hz
from ictus_tools.presets import preset_air_mass, preset_head

MYLAR = (4.5e9, 0.38, 1390.0)  # E (Pa), nu, rho (kg/m^3): docs/membrane.md
SPACING_S = 2.0


def begley_mackin_k3(radius_m, density_kg_per_m2):
    """k3 = E h q^3 / a^2, h = density / rho (N/m^3)."""
    e, nu, rho = MYLAR
    q = 1.0 / (1.05 - 0.15 * nu - 0.16 * nu * nu)
    return e * (density_kg_per_m2 / rho) * q ** 3 / radius_m ** 2


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", required=True)
    ap.add_argument("--preset", default="tom")
    ap.add_argument("--mass", type=float, default=0.0138)
    ap.add_argument("--ra", type=float, default=0.33)
    ap.add_argument("--stretch", type=float, default=None)
    ap.add_argument("--drum", action="append", default=[],
                    help="a message to the drum after the preset, e.g. 'cascade 1' (repeatable)")
    ap.add_argument("--speeds", default="0.46,1.02,1.58,2.18,2.77,3.37,3.99,4.61,5.24,5.87")
    a = ap.parse_args()
    head = dict(zip(("radius", "tension", "density"), preset_head(a.preset)))
    head["airmass"] = preset_air_mass(a.preset)
    for msg in a.drum:  # the head as the --drum messages leave it
        words = msg.split()
        if len(words) == 2 and words[0] in head:
            head[words[0]] = float(words[1])
    radius, tension, density = head["radius"], head["tension"], head["density"]
    k3 = begley_mackin_k3(radius, density) if a.stretch is None else a.stretch
    speeds = [float(v) for v in a.speeds.split(",")]
    f01, f11, f21 = (mode_hz(radius, tension, density, m, 1, head["airmass"]) for m in (0, 1, 2))
    print("%s: a %.4f m, T %g N/m, sigma %g kg/m^2, airmass %g; f01 %.0f, f11 %.0f, f21 %.0f "
          "Hz; stick %.4f kg at r/a %.2f, k3 %.3g N/m^3"
          % (a.preset, radius, tension, density, head["airmass"], f01, f11, f21, a.mass, a.ra, k3))
    work = tempfile.mkdtemp(prefix="ictus-contact-probe-")
    events = os.path.join(work, "events.txt")
    with open(events, "w") as f:
        for line in ["render-drum preset %s" % a.preset] + \
                ["render-drum %s stretch %.9g" % (h, k3) for h in ("left", "right")] + \
                ["render-drum " + msg for msg in a.drum]:
            f.write("0 %s;\n" % line)
        for i, v in enumerate(speeds):
            t = 0.1 + SPACING_S * i
            f.write("%.3f hit 1 0 0 %.4f %.4f 0 0 0 0 0 %.6f %.5f;\n"
                    % (100.0 if i == 0 else 1000.0 * SPACING_S, v, a.ra, t, a.mass))
    wav, reports = os.path.join(work, "probe.wav"), os.path.join(work, "reports.txt")
    cmd = PD_BATCH + ["-r", "48000", "-path", os.path.join(os.path.abspath(a.build), "ictus"),
                      "-open", os.path.join(ROOT, "patches", "ictus-render.pd"), "-send",
                      "render-file " + events, "-send", "render-out " + wav, "-send",
                      "render-mix pickups", "-send", "render-gain -40", "-send",
                      "render-seconds %.3f" % (0.6 + SPACING_S * len(speeds)), "-send",
                      "render-reports " + reports]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=600, env=PD_ENV)
    errors = error_lines(proc.stdout + proc.stderr)
    if proc.returncode != 0 or errors:
        raise SystemExit("pd failed: %s" % (errors or proc.stderr[-2000:]))
    x, sr, _, _ = read_wav_any(wav)
    with open(reports) as f:
        reps = [[float(w) for w in r.split()] for r in f.read().split(";") if r.split()]
    cut1, cut2 = 0.5 * (f01 + f11), 0.5 * (f11 + f21)
    print("  v m/s  contact ms  peak N  RMS dB  centroid Hz  (0,1) band  (1,1) band  rebound m/s")
    for i, v in enumerate(speeds):
        t = 0.1 + SPACING_S * i
        rep = min((r for r in reps if r[0] >= t * 1e3 - 1.0), key=lambda r: r[0])
        n0 = int(round(t * sr))
        rms = x[n0:n0 + int(0.1 * sr)]
        seg = x[n0:n0 + int(0.05 * sr)]
        p = np.sum(np.abs(np.fft.rfft(seg * np.hanning(len(seg))[:, None], axis=0)) ** 2, axis=1)
        f = np.fft.rfftfreq(len(seg), 1.0 / sr)
        print("  %5.2f  %10.2f  %6.1f  %6.1f  %11.0f  %9.0f%%  %9.0f%%  %11.2f"
              % (v, rep[2], rep[3], 10 * math.log10(np.mean(np.sum(rms ** 2, axis=1)) + 1e-30),
                 np.sum(p * f) / np.sum(p), 100 * np.sum(p[f < cut1]) / np.sum(p),
                 100 * np.sum(p[(f >= cut1) & (f < cut2)]) / np.sum(p), rep[4]))


if __name__ == "__main__":
    main()
