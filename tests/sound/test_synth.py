"""[ictus-sound-synth] rings at the ideal membrane's frequencies and decays as
told, in real pd batch mode.

Theory (scipy, independent of the patch): f_mn = j_mn / (2 pi a) sqrt(T / sigma)
with j_mn the Bessel zeros; default head a = 0.178 m, T = 3000 N/m,
sigma = 0.262 kg/m^2 gives f01 = 230.0 Hz. One stroke at r/a 0.3, theta 30 deg,
then `tension 4500` and another: every spectral peak of the first six modes must
sit within 0.1 % of theory (the bp~ filters are tuned with Pd's polynomial
cosine), and all move by sqrt(4500/3000). The fundamental's decay follows t60
(set to 0.5 s): the amplitude of a narrow band around f01 falls 60 dB in
0.5 s +- 5 %."""
import argparse
import os

import numpy as np
from scipy import signal, special

from ictus_tools.checks import check
from ictus_tools.soundrun import make_workdir, render, write_events

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
build = os.path.abspath(args.build)
work = make_workdir("ictus-sound-synth-")
sr = 48000

zeros = sorted((special.jn_zeros(m, 3)[n], m) for m in range(6) for n in range(3))[:6]


def theory(tension):
    return [j / (2 * np.pi * 0.178) * np.sqrt(tension / 0.262) for j, m in zeros]


items = [(100.0, 0, 3.0, 0.3, 30.0), (1990.0, "render-drum tension 4500"), (2000.0, 0, 3.0, 0.3, 30.0)]
events = os.path.join(work, "events.txt")
write_events(events, items, head=["render-drum t60 0.5"])
x = render(build, "synth", events, os.path.join(work, "synth.wav"), 3.9)
y = x[:, 0]
for start, tension in ((100.0, 3000.0), (2000.0, 4500.0)):
    a = int((start + 5) * sr / 1000)
    # both pickups' magnitude spectra: a mode silent at one pickup rings at the other
    spec = sum(np.abs(np.fft.rfft(x[a:a + sr, c] * np.hanning(sr), 8 * sr)) for c in (0, 1))
    freqs = np.fft.rfftfreq(8 * sr, 1.0 / sr)
    found = []
    for f in theory(tension):
        band = (freqs > f * 0.97) & (freqs < f * 1.03)
        found.append(float(freqs[band][np.argmax(spec[band])]))
    errs = [g / f - 1 for g, f in zip(found, theory(tension))]
    print("tension %g: theory %s Hz, found %s Hz" % (tension, ["%.1f" % f for f in theory(tension)],
                                                      ["%.1f" % f for f in found]))
    check(all(abs(e) < 0.001 for e in errs),
          "tension %g N/m: the first six modes within 0.1 %% of j_mn/(2 pi a) sqrt(T/sigma): %s"
          % (tension, ["%+.2f%%" % (100 * e) for e in errs]))
# decay of the fundamental (first stroke): band around f01, envelope in dB
f01 = theory(3000.0)[0]
sos = signal.butter(4, [f01 * 0.92, f01 * 1.08], "bandpass", fs=sr, output="sos")
band = signal.sosfiltfilt(sos, y[:int(1.9 * sr)])
env = np.abs(signal.hilbert(band))
t = np.arange(len(env)) / sr
fit = (t > 0.2) & (t < 0.9)
slope = np.polyfit(t[fit], 20 * np.log10(env[fit]), 1)[0]
t60 = -60.0 / slope
check(abs(t60 / 0.5 - 1) < 0.05, "the fundamental decays 60 dB in %.3f s (t60 0.5 s)" % t60)

# The tables stored in the abstraction (mode ratios and orders; mode-shape
# weights eps_m J_m(j r) J_m(j 0.5) / J_{m+1}(j)^2 at r/a = 0, 0.025 .. 1) match
# scipy's Bessel functions.
text = open(os.path.join(build, "ictus", "ictus-sound-synth.pd")).read().splitlines()
arrays = {}
for i, line in enumerate(text):
    if "array define -k" in line:
        name = line.split("array define -k")[1].split()[0].replace("\\$0-", "")
        arrays[name] = np.array([float(v) for v in text[i + 1].rstrip(";").split()[2:]])
modes12 = sorted((special.jn_zeros(m, 4)[n], m) for m in range(8) for n in range(4))[:12]
want_modes = np.array([[j / modes12[0][0], m] for j, m in modes12]).ravel()
r = np.linspace(0, 1, 41)
want_shape = np.concatenate([(1.0 if m == 0 else 2.0) * special.jv(m, j * r) * special.jv(m, j * 0.5)
                             / special.jv(m + 1, j) ** 2 for j, m in modes12])
check(arrays.get("modes") is not None and np.allclose(arrays["modes"], want_modes, rtol=1e-5),
      "mode ratios j_mn/j_01 and orders m as scipy's Bessel zeros")
check(arrays.get("shape") is not None and np.allclose(arrays["shape"], want_shape, atol=1e-5),
      "mode-shape weights as scipy's Bessel functions (12 x 41)")

# Position: a strike at the centre (r/a 0) excites only the axisymmetric modes
# (J_m(0) = 0 for m > 0): the (1,1) mode at 366.6 Hz is > 40 dB below the
# fundamental there, while a strike at r/a 0.5 excites it within 20 dB.
items = [(100.0, 0, 3.0, 0.0, 0.0), (1100.0, 0, 3.0, 0.5, 0.0)]
events = os.path.join(work, "position.txt")
write_events(events, items, head=["render-drum t60 0.5"])
x = render(build, "synth", events, os.path.join(work, "position.wav"), 2.1)
f01, f11 = theory(3000.0)[0], theory(3000.0)[1]
for start, r_over_a, lo, hi in ((100.0, 0.0, -400, -40), (1100.0, 0.5, -20, 20)):
    a = int((start + 5) * sr / 1000)
    spec = np.abs(np.fft.rfft(x[a:a + int(0.9 * sr), 0] * np.hanning(int(0.9 * sr)), 8 * sr))
    freqs = np.fft.rfftfreq(8 * sr, 1.0 / sr)

    def peak(f):
        return spec[(freqs > f * 0.99) & (freqs < f * 1.01)].max()
    db = 20 * np.log10(peak(f11) / peak(f01))
    check(lo < db < hi, "strike at r/a %g: mode (1,1) is %.1f dB relative to (0,1), in (%g, %g)"
          % (r_over_a, db, lo, hi))

# Velocity -> brightness: the power-weighted spectral centroid of the first
# 50 ms (both pickups) rises with velocity, by at least 1.3x from 0.7 to 5.6 m/s
# (the exciter's low-pass opens with velocity and its click grows faster than
# the resonators).
velocities = [0.7, 1.4, 2.8, 5.6]
items = [(100.0 + 500.0 * i, 0, v, 0.3, 30.0) for i, v in enumerate(velocities)]
events = os.path.join(work, "brightness.txt")
write_events(events, items, head=["render-drum t60 0.3"])
x = render(build, "synth", events, os.path.join(work, "brightness.wav"), 2.2)
centroids = []
for t, hand, v, r_over_a, theta in items:
    a = int(np.floor(t * sr / 1000.0 + 0.5))
    power = sum(np.abs(np.fft.rfft(x[a:a + int(0.05 * sr), c], sr)) ** 2 for c in (0, 1))
    freqs = np.fft.rfftfreq(sr, 1.0 / sr)
    centroids.append(float((power * freqs).sum() / power.sum()))
check(all(b > a for a, b in zip(centroids, centroids[1:])) and centroids[-1] > 1.3 * centroids[0],
      "spectral centroid over 50 ms rises with velocity %s: %s Hz"
      % (velocities, ["%.0f" % c for c in centroids]))
