"""[ictus-sound] switches models live, mid-render: an events file plays
modal, switches to synth 10 ms after a stroke (the modal head still ringing),
then to clips, back to modal, then halves the volume (`render-drum model ...` /
`render-drum volume 0.5` lines, i.e. messages to [ictus-sound] at their logical
time, with the default 20 ms crossfade).

Independent reference: each model rendered alone (render-model X) with only the
strokes the switched render gives it. From 40 ms after a switch the old model
is faded out and the new one fully in, so each stroke's window must equal the
reference of its model (x 0.5 after the volume change) to float precision —
which also shows the sound before and after every switch is the right model
and not silent. Everything is finite; during each crossfade the largest
sample-to-sample step is no larger than the ringing's own just before it (no
click)."""
import argparse
import os

import numpy as np

from ictus_tools.checks import check
from ictus_tools.soundrun import make_workdir, render, write_events

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
build = os.path.abspath(args.build)
work = make_workdir("ictus-sound-switch-")
sr = 48000

# (time ms, model, hand, velocity, r/a, theta); switches at (time, "model X")
strokes = [(100.0, "modal", 0, 2.0, 0.3, 30.0), (300.0, "modal", 1, 3.0, 0.4, 60.0),
           (350.0, "synth", 0, 2.0, 0.3, 30.0), (600.0, "synth", 1, 3.0, 0.5, 10.0),
           (650.0, "clips", 0, 2.0, 0.3, 30.0), (1700.0, "clips", 1, 3.0, 0.6, 0.0),
           (1750.0, "modal", 0, 2.0, 0.3, 30.0), (2100.0, "modal", 1, 3.0, 0.3, 30.0)]
switches = [(310.0, "render-drum model synth"), (610.0, "render-drum model clips"),
            (1710.0, "render-drum model modal"), (2000.0, "render-drum volume 0.5")]
seconds = 2.4
items = sorted([(t, h, v, r, th) for t, m, h, v, r, th in strokes] + switches, key=lambda i: i[0])
events = os.path.join(work, "switched.txt")
write_events(events, items, head=["render-drum t60 0.02"])
x = render(build, "modal", events, os.path.join(work, "switched.wav"), seconds, sr)
check(np.all(np.isfinite(x)), "switched render: finite")

ref = {}
for model in ("modal", "synth", "clips"):
    ev = os.path.join(work, "%s.txt" % model)
    write_events(ev, [(t, h, v, r, th) for t, m, h, v, r, th in strokes if m == model],
                 head=["render-drum t60 0.02"])
    ref[model] = render(build, model, ev, os.path.join(work, "%s.wav" % model), seconds, sr)

for (t, model, h, v, r, th) in strokes:
    # up to the next stroke or switch (a window never contains a crossfade)
    end = min([u for u in [s[0] for s in strokes] + [w[0] for w in switches] if u > t]
              + [seconds * 1000.0])
    a, b = int(t * sr / 1000) - 10, int(end * sr / 1000) - 10
    scale = 0.5 if t > 2000.0 else 1.0
    want = scale * ref[model][a:b]
    got = x[a:b]
    err = float(np.abs(got - want).max())
    level = float(np.sqrt((want ** 2).mean()))
    check(level > 1e-3 and err <= 1e-6 * max(1.0, float(np.abs(want).max())) + 1e-7,
          "stroke at %g ms plays %s%s: max |switched - alone| = %.2g (RMS %.4f)"
          % (t, model, " at volume 0.5" if scale != 1.0 else "", err, level))



def steps(y, t):
    """largest sample-to-sample step in the 10 ms before a switch, and from the
    sample before it through the 20 ms fade"""
    s = int(t * sr / 1000)
    return (float(np.abs(np.diff(y[s - 480:s], axis=0)).max()),
            float(np.abs(np.diff(y[s - 1:s + 960], axis=0)).max()))


for t, what in switches[:3]:
    before, during = steps(x, t)
    check(before > 1e-4 and during <= before,
          "%s at %g ms: largest step in the 20 ms fade %.3g <= just before %.3g"
          % (what, t, during, before))

# The same check catches a click: without the fade (fade 0) the ringing model is
# cut off at once, a step larger than any of its ringing.
events0 = os.path.join(work, "switched-nofade.txt")
write_events(events0, items, head=["render-drum t60 0.02", "render-drum fade 0"])
x0 = render(build, "modal", events0, os.path.join(work, "switched-nofade.wav"), seconds, sr)
for t in (310.0, 1710.0):
    before, during = steps(x0, t)
    check(during > before, "control: with fade 0 the switch at %g ms is a click (%.3g > %.3g)"
          % (t, during, before))
