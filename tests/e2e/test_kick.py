"""The `kick` preset as a listener hears it: `ictusd render --drum-preset kick --stick-tip felt`
(the real daemon and pd) plays seeded random strikes near the centre, where a bass drum's
beater lands (r/a 0.05 .. 0.25), at seeded random dynamics.

Asserted for every primary strike, on the WAV's first pickup:
1. its fundamental, the lowest spectral peak of the first 5 .. 65 ms within 20 dB of the
   strongest (20 .. 400 Hz), lies below 100 Hz;
2. it is the head's (0,1) mode: within -3 % .. +8 % of j01 / (2 pi a) sqrt(T / sigma),
   computed here from render.json's drum (radius, tension, density) - above it only by the
   tension modulation's glide, which raises a loud hit's pitch (docs/sound.md);
3. the WAV is finite and not silent.
(The strongest peak may be (1,1), 1.59 times higher: the pickups hear the head's velocity
at r/a 0.5, where (1,1) moves as much as (0,1), not the radiated sound a microphone hears.)
"""
import argparse
import csv
import json
import math
import os
import random
import subprocess

import numpy as np

from ictus_tools import e2e_util as u
from ictus_tools.checks import check
from ictus_tools.drumtone import lowest_peak_hz
from ictus_tools.pdrun import make_workdir, read_wav_float

J01 = 2.404825557695773  # first zero of J0
DYNAMICS = ["pp", "p", "mp", "mf", "f", "ff"]
ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
work = make_workdir("ictus-kick-")
rng = random.Random(30)
notes = [(round(rng.uniform(0.05, 0.25), 3), rng.choice(DYNAMICS)) for _ in range(6)]
score = ["tempo 60"] + ["R legato %s at %.3f 180" % (d, r) for r, d in notes]
path = os.path.join(work, "kick.score")
with open(path, "w") as f:
    f.write("\n".join(score) + "\n")
out = os.path.join(work, "out")
wav = os.path.join(out, "kick.wav")
subprocess.run([os.path.join(args.build, "ictusd"), "render", "--score", path, "--out", out,
                "--drum-preset", "kick", "--stick-tip", "felt", "--wav", wav, "--wav-mix",
                "pickups", "--wav-bits", "32"], check=True, timeout=600,
               stdout=subprocess.DEVNULL, env=u.pd_spawning_env(work))
drum = json.load(open(os.path.join(out, "render.json")))["drum"]
check(drum["preset"] == "kick", "render.json names the preset: %s" % drum["preset"])
f01 = J01 / (2.0 * math.pi * drum["radius_m"]) * math.sqrt(drum["tension_n_per_m"]
                                                          / drum["density_kg_per_m2"])
print("score:", score[1:])
print("the head's (0,1) from render.json: %.2f Hz" % f01)
x, sr = read_wav_float(wav)
y = x[:, 0].astype(np.float64)
check(np.all(np.isfinite(y)) and np.max(np.abs(y)) > 1e-4, "the WAV is finite and sounds")
rows = [r for r in csv.DictReader(open(os.path.join(out, "strikes.csv"))) if r["bounce"] == "0"]
check(len(rows) == len(notes), "one primary strike per note: %d of %d" % (len(rows), len(notes)))
for r in rows:
    fundamental = lowest_peak_hz(y, sr, int(round(float(r["time_s"]) * sr)))
    what = "strike at %s s, r/a %s, %s m/s" % (r["time_s"], r["r_over_a"],
                                               r["normal_velocity_mps"])
    check(fundamental < 100.0, "%s: fundamental %.1f Hz, below 100 Hz" % (what, fundamental))
    check(0.97 * f01 <= fundamental <= 1.08 * f01,
          "%s: the fundamental is the (0,1) mode: %.1f Hz against %.1f Hz (-3 %% .. +8 %%)"
          % (what, fundamental, f01))
