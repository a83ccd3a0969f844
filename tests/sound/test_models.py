"""The three sound models play the SAME events file (the qlist format of
ictus-render.pd / `ictusd render`) through patches/sound/ictus-sound-render.pd
in real pd batch mode, and each one:

* sounds: finite, non-silent, and never beyond |y| = 1 (velocities up to 5.6 m/s);
* starts every stroke on sample round(t * sr / 1000), the sample membrane~ and
  contact~ start on (docs/externals.md): the modal model by construction, the
  clips and synth models through [vline~] with a half-sample delay. Tolerance:
  0 samples for all three. The onset is the first sample above 1e-6 after at
  least 200 quiet samples; the events file's first line sets t60 0.02 s (modal
  and synth follow it) and strokes are 1 s apart (the clips are silent after
  0.95 s), so each stroke starts from silence;
* is louder for a faster stick: RMS over the first 50 ms rises with velocity
  (0.7, 1.4, 2.8, 5.6 m/s, twice), and each doubling of the velocity multiplies
  it by 1.5 .. 2.5. Expected: a linear resonator driven by a contact whose force
  scales with velocity doubles (2x); the bounds leave room for the contact's
  nonlinearity (modal, clips) and the synth's velocity-dependent brightness.
The clips model also runs at 44.1 kHz (clips are 48 kHz files): same onsets."""
import argparse
import os

import numpy as np

from ictus_tools.checks import check
from ictus_tools.soundrun import MODELS, make_workdir, onsets, render, rms, write_events

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
build = os.path.abspath(args.build)
work = make_workdir("ictus-sound-models-")

velocities = [0.7, 1.4, 2.8, 5.6]
rng = np.random.default_rng(7)
strokes = []
for i in range(8):
    # fractional ms, away from half-sample ties at 44.1 and 48 kHz
    while True:
        t = round(100.0 + 1000.0 * i + rng.uniform(0, 5), 3)
        if all(abs((t * sr / 1000.0) % 1.0 - 0.5) > 0.1 for sr in (44100, 48000)):
            break
    strokes.append((t, i % 2, velocities[i % 4], 0.3, 30.0))
events = os.path.join(work, "events.txt")
write_events(events, strokes, head=["render-drum t60 0.02"])
seconds = 8.2
times = [s[0] for s in strokes]

for model, sr in [(m, 48000) for m in MODELS] + [("clips", 44100)]:
    x = render(build, model, events, os.path.join(work, "%s-%d.wav" % (model, sr)), seconds, sr)
    tag = "%s at %d Hz" % (model, sr)
    check(np.all(np.isfinite(x)), "%s: finite output" % tag)
    peak = float(np.abs(x).max())
    check(0.05 < peak <= 1.0, "%s: sounds, peak %.3f within (0.05, 1]" % (tag, peak))
    found = onsets(x, times, sr)
    expected = [int(np.floor(t * sr / 1000.0 + 0.5)) for t in times]
    y = np.abs(x).max(axis=1)
    quiet = all(o > 0 and y[o - 200:o].max() <= 1e-6 for o in found)
    check(quiet, "%s: silence before every stroke" % tag)
    diff = [o - e for o, e in zip(found, expected)]
    print("%s: onset - round(t * sr) (samples): %s" % (tag, diff))
    check(all(d == 0 for d in diff), "%s: every stroke starts on sample round(t * sr / 1000)" % tag)
    r = [rms(x, o, 50, sr) for o in found]
    print("%s: RMS over 50 ms by velocity %s: %s" % (tag, velocities * 2, ["%.4g" % v for v in r]))
    for k in (0, 4):
        ratios = [r[k + j + 1] / r[k + j] for j in range(3)]
        check(all(1.5 <= q <= 2.5 for q in ratios),
              "%s: doubling the velocity multiplies the RMS by 1.5..2.5: %s"
              % (tag, ["%.3f" % q for q in ratios]))
