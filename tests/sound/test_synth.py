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
import sys

import numpy as np
from scipy import signal, special

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from soundrun import check, make_workdir, render, write_events  # noqa: E402

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
