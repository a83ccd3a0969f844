"""What a listener hears from `ictusd render` (docs/sound.md, "Expression"), measured in the
WAV, pickups mix, -20 dB, 32-bit float (far below the soft limiter), on the `tom` preset:

- the ladder `R legato D`, D = 0.1 .. 1.0, one note every 2 s: the level (RMS of the first
  100 ms after each note's strike) rises monotonically and spans >= 26 dB (a drum spans
  30-40 dB from pp to ff); the spectral centroid of the first 50 ms at ff is >= 1.5 times pp's (a
  recorded tom's soft and hard hits: 165 -> 248 Hz) and rises at every step;
- the pitch glide (tension modulation): the (1,1) partial, the tom's pitch, read 5-65 ms
  after the strike is >= 10 cents above its pitch 400-460 ms after for ff, and within 2 cents
  for pp. The partial is found as the spectral peak within 10 % of the ideal membrane's
  f11 = j11 c / (2 pi a), c = sqrt(T / sigma), from render.json's radius, tension and density,
  with the air's mass the preset puts on it (ictus_tools.drumtone.mode_hz: the theory, its g by
  a route of its own, independent of the sound code);
- the grid pp / mf / ff x the five nuances: every pp quieter than every mf, every mf than
  every ff (dynamics outrank nuance).

    /usr/bin/python3 tests/e2e/test_expression.py --build build
"""
import argparse
import csv
import json
import math
import os
import subprocess
import sys

import numpy as np
from scipy.signal.windows import blackmanharris

from ictus_tools import e2e_util as u
from ictus_tools.checks import check, finish, keep_going
from ictus_tools.drumtone import mode_hz
from ictus_tools.pdrun import make_workdir, read_wav_any
from ictus_tools.presets import preset_air_mass

LADDER = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0]
NUANCES = ["legato", "tenuto", "accent", "vertical_accent", "staccato"]
LEVELS = [("pp", 0.2), ("mf", 0.6), ("ff", 1.0)]
SPACING_S = 2.0           # tempo 30: each note rings 2 s before the next

ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
ap.add_argument("--build", required=True)
ap.add_argument("--preset", default="tom")
args = ap.parse_args()
ictusd = os.path.join(os.path.abspath(args.build), "ictusd")
work = make_workdir("ictus-expression-")
env = u.pd_spawning_env(work)


def render(name, words):
    """Right-hand notes SPACING_S apart -> (mono-power signal per pickup, sr, note strikes,
    render.json)."""
    score = os.path.join(work, name + ".score")
    with open(score, "w") as f:
        f.write("tempo %g\n" % (60.0 / SPACING_S))
        f.writelines("R %s\n" % w for w in words)
    out = os.path.join(work, name)
    cmd = [ictusd, "render", "--score", score, "--out", out, "--drum-preset", args.preset,
           "--wav", os.path.join(out, "p.wav"), "--wav-mix", "pickups", "--wav-gain", "-20",
           "--wav-bits", "32", "--bvh-rate", "0", "--tips-rate", "0", "--progress-every", "0"]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=900, env=env)
    if proc.returncode != 0:
        print(proc.stderr[-3000:])
        sys.exit("ictusd render failed")
    x, sr, _, _ = read_wav_any(os.path.join(out, "p.wav"))
    with open(os.path.join(out, "notes.csv")) as f:
        notes = list(csv.DictReader(f))
    with open(os.path.join(out, "strikes.csv")) as f:
        strikes = {r["seq"]: r for r in csv.DictReader(f)}
    times = []
    for n in notes:
        s = strikes.get(n.get("strike_seq", ""))
        check(s is not None, "%s: note at %s s has its strike" % (name, n.get("time_s")))
        times.append(float(s["time_s"]) if s else float("nan"))
    with open(os.path.join(out, "render.json")) as f:
        drum = json.load(f)["drum"]
    return x, sr, times, drum


def segment(x, sr, t, start_s, length_s):
    i = int(round((t + start_s) * sr))
    return x[i:i + int(round(length_s * sr))]


def level_db(x, sr, t):
    seg = segment(x, sr, t, 0.0, 0.100)
    return 10.0 * math.log10(np.mean(np.sum(seg ** 2, axis=1)) + 1e-30)


def centroid_hz(x, sr, t):
    seg = segment(x, sr, t, 0.0, 0.050)
    w = np.hanning(len(seg))[:, None]
    power = np.sum(np.abs(np.fft.rfft(seg * w, axis=0)) ** 2, axis=1)
    f = np.fft.rfftfreq(len(seg), 1.0 / sr)
    return float(np.sum(power * f) / np.sum(power))


def peak_hz(seg, sr, f_lo, f_hi):
    """The spectral peak between f_lo and f_hi (4-term Blackman-Harris window, zero-padded to
    2^20 points: a 0.05 Hz grid). Its side lobes lie 92 dB down: a Hann window's skirt from
    the (0,1), 20 dB above (1,1) at pp and 86 Hz below it, pulled the peak 2.8 cents up in
    the early window of a pp stroke with the tension modulation off, where nothing glides."""
    mono = seg.sum(axis=1)
    n = 1 << 20
    spec = np.abs(np.fft.rfft(mono * blackmanharris(len(mono)), n))
    f = np.fft.rfftfreq(n, 1.0 / sr)
    band = (f > f_lo) & (f < f_hi)
    return float(f[band][np.argmax(spec[band])])


def glide_cents(x, sr, t, f11):
    early = peak_hz(segment(x, sr, t, 0.005, 0.060), sr, 0.9 * f11, 1.1 * f11)
    late = peak_hz(segment(x, sr, t, 0.400, 0.060), sr, 0.9 * f11, 1.1 * f11)
    return 1200.0 * math.log2(early / late)


def monotone(values):
    return all(b > a for a, b in zip(values, values[1:]))


keep_going()
x, sr, times, drum = render("ladder", ["legato %g" % d for d in LADDER])
f11 = mode_hz(drum["radius_m"], drum["tension_n_per_m"], drum["density_kg_per_m2"], 1, 1,
              preset_air_mass("tom"))
levels = [level_db(x, sr, t) for t in times]
centroids = [centroid_hz(x, sr, t) for t in times]
glides = [glide_cents(x, sr, t, f11) for t in times]
for d, lv, ce, gl in zip(LADDER, levels, centroids, glides):
    print("d %.1f: level %6.1f dB, centroid %5.0f Hz, glide of (1,1) %+6.1f cents" % (d, lv, ce, gl))
span = levels[-1] - levels[0]
check(monotone(levels), "ladder: level rises with every step")
# The stroke heights (d^1.3, docs/gestures.md) give the ladder 21x in impact speed.
check(span >= 26.0, "ladder: level range %.1f dB (a drum: 26 dB and more)" % span)
# The head's energy cascade brightens a ff hit (docs/membrane.md), and the shortening contact
# moves energy up from (0,1) at every step (docs/membrane.md, "The air's mass").
check(centroids[-1] >= 1.5 * centroids[0], "ladder: centroid ff/pp %.2f (>= 1.5; a recorded tom: 1.5)"
      % (centroids[-1] / centroids[0]))
check(monotone(centroids), "ladder: the centroid rises at every step")
check(glides[-1] >= 10.0, "ff: (1,1) starts %.1f cents sharp (>= 10)" % glides[-1])
check(abs(glides[0]) <= 2.0, "pp: (1,1) glides %.1f cents (<= 2)" % glides[0])

words, labels = [], []
for name, d in LEVELS:
    for n in NUANCES:
        words.append("%s %g" % (n, d))
        labels.append((name, n))
x, sr, times, _ = render("grid", words)
grid = {lab: level_db(x, sr, t) for lab, t in zip(labels, times)}
for name, _ in LEVELS:
    print("%s: " % name + ", ".join("%s %.1f dB" % (n, grid[(name, n)]) for n in NUANCES))
for soft, loud in (("pp", "mf"), ("mf", "ff")):
    loudest_soft = max(grid[(soft, n)] for n in NUANCES)
    softest_loud = min(grid[(loud, n)] for n in NUANCES)
    check(loudest_soft < softest_loud,
          "every %s (at most %.1f dB) quieter than every %s (at least %.1f dB)" %
          (soft, loudest_soft, loud, softest_loud))
finish()
