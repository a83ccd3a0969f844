"""[ictus-sound-clips] picks the velocity layer and position variant the
documented rule names, and scales the level within the layer.

The rule, computed here independently of the patch: layer = round(log2(v / 0.75))
clamped to 0..3 (layers rendered at 0.75 1.5 3 6 m/s), position = nearest of
r/a 0.15 0.4 0.7, gain = v / (0.75 * 2^layer). The clip file the build rendered
(<build>/ictus/clips/ictus-clips.wav: 12 clips of 48000 frames, frame 0 silent)
is read here, and each stroke's output (both pickups, first 100 ms) is compared
with gain x that clip read at the fractional position the voice's [vline~]
gives (sample n reads frame n + 1 - t*sr - 0.5, at least 1; linear
interpolation here, 4-point in the patch). The right clip must match
(normalised correlation > 0.9999, fitted gain within 0.5 % of the rule's); the
other layer at the same position must match worse (the layers are distinct
renders: a faster stick gives a shorter, relatively brighter contact).
Velocities straddle every layer boundary (1.06, 2.12, 4.24 m/s) and go beyond
both ends; the level still rises with velocity across each boundary."""
import argparse
import os
import wave

import numpy as np

from ictus_tools.checks import check
from ictus_tools.soundrun import make_workdir, render, write_events

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
build = os.path.abspath(args.build)
work = make_workdir("ictus-sound-clips-")

# the clip file: 24-bit stereo
path = os.path.join(build, "ictus", "clips", "ictus-clips.wav")
with wave.open(path) as w:
    check(w.getnchannels() == 2 and w.getsampwidth() == 3 and w.getframerate() == 48000
          and w.getnframes() == 12 * 48000, "the clip file is 2 x 24 bit, 48 kHz, 12 x 48000 frames")
    raw = np.frombuffer(w.readframes(w.getnframes()), dtype=np.uint8).reshape(-1, 3)
ints = (raw[:, 0].astype(np.int32) | (raw[:, 1].astype(np.int32) << 8)
        | (raw[:, 2].astype(np.int32) << 16))
ints = np.where(ints >= 1 << 23, ints - (1 << 24), ints)
clips = (ints / float(1 << 23)).reshape(12, 48000, 2)
check(np.all(clips[:, 0, :] == 0) and np.all(np.abs(clips[:, 1, :]).max(axis=1) > 0),
      "every clip has a silent frame 0 and sound from frame 1")


def rule(v, r):
    layer = int(min(max(np.floor(np.log2(v / 0.75) + 0.5), 0), 3))
    pos = 0 if r < 0.275 else (1 if r < 0.55 else 2)
    return 3 * layer + pos, v / (0.75 * 2 ** layer)


cases = [(0.3, 0.3), (0.75, 0.3), (1.0, 0.3), (1.12, 0.3), (2.0, 0.3), (2.25, 0.3),
         (4.0, 0.3), (4.5, 0.3), (8.0, 0.3), (1.5, 0.1), (1.5, 0.5), (1.5, 0.9),
         (6.0, 0.2), (3.0, 0.6)]
sr = 48000
strokes = [(round(100.0 + 1000.0 * i + 0.0123 * i, 3), i % 2, v, r, 30.0)
           for i, (v, r) in enumerate(cases)]
events = os.path.join(work, "events.txt")
write_events(events, strokes)
seconds = len(cases) + 0.2
x = render(build, "clips", events, os.path.join(work, "clips.wav"), seconds, sr)
n = int(0.1 * sr)
levels = []
for (t, hand, v, r, theta) in strokes:
    k, g = rule(v, r)
    t0 = t * sr / 1000.0
    n0 = int(np.floor(t0 + 0.5))
    idx = np.maximum(np.arange(n0, n0 + n) + 1 - t0 - 0.5, 1.0)
    out = x[n0:n0 + n]

    def expect(clip):
        return np.stack([np.interp(idx, np.arange(48000), clips[clip, :, c]) for c in (0, 1)], 1)

    def ncc(a, b):
        return float((a * b).sum() / np.sqrt((a * a).sum() * (b * b).sum()))

    e = expect(k)
    c_right = ncc(out, e)
    gain = float((out * e).sum() / (e * e).sum())
    other = k + 3 if k < 9 else k - 3
    c_other = ncc(out, expect(other))
    print("v %.2f r/a %.2f: clip %d (rule), ncc %.6f, gain %.4f (rule %.4f); clip %d ncc %.6f"
          % (v, r, k, c_right, gain, g, other, c_other))
    check(c_right > 0.9999 and abs(gain / g - 1) < 0.005,
          "v %.2f m/s, r/a %.2f plays clip %d at gain %.3f" % (v, r, k, g))
    check(c_other < c_right - 1e-4, "v %.2f m/s: the other layer (clip %d) matches worse" % (v, other))
    levels.append(float(np.sqrt((out ** 2).mean())))
rising = [levels[i + 1] > levels[i] for i in range(8)]
check(all(rising), "level rises with velocity across the layer boundaries: %s"
      % ["%.4f" % l for l in levels[:9]])
