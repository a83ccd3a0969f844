"""[ictus-sound-synth] retuned while it rings (t60, tension, radius, density, mass changed
between strokes, as the sound panel's sliders do): the ringing carries on from where it was and
decays at the new rate, never louder than before the change. Its resonators were Pd's [bp~],
whose output is the filter state times a gain that grows with the bandwidth: `t60 0.005` sent
while a 5 m/s stroke rang (peak 0.5) gave a click of 60 (found writing a patch by hand). They are
now [biquad~]s with bp~'s coefficients (Pd's polynomial cosine included) and bp~'s gain on the
input, so each stroke sounds as before (within float rounding) and a change moves no sample:
the ringing goes on from its last two samples. A change of the decay, or a higher pitch, never
makes it louder; a lower pitch can, by at most the ratio of the frequencies (two samples of a
slow oscillation stand for a larger one), as membrane~'s modes do under a parametric drive
(docs/membrane.md, "Parameter changes while sounding")."""
import argparse
import os

import numpy as np

from ictus_tools.checks import check, keep_going, failed
from ictus_tools.pdrun import Patch, recorder, run_recorded

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
args.build = os.path.abspath(args.build)
SR = 48000
CHANGE = 0.1  # s

keep_going()
AREA = np.pi * 0.178 ** 2
# (message, the factor by which it lowers every mode's frequency, 1 when it does not)
for change, lower in (("t60 0.005", 1.0), ("t60 0.02", 1.0), ("t60 60", 1.0),
                      ("tension 9000", 1.0), ("radius 0.05", 1.0), ("density 0.05", 1.0),
                      ("tension 500", np.sqrt(3000 / 500)),
                      ("mass 0.5", np.sqrt(0.5 / AREA / 0.262))):
    p = Patch()
    synth = p.obj("ictus-sound-synth")
    trig = recorder(p, [(synth, 0, "a"), (synth, 1, "b")], 0.3, SR, "WAV")
    for ms, text in ((5.0, "1 5 0.3 30"), (CHANGE * 1000, change)):
        d = p.obj("delay %g" % ms)
        m = p.msg(text)
        p.connect(trig, 0, d, 0)
        p.connect(d, 0, m, 0)
        p.connect(m, 0, synth, 0)
    rc, log, y = run_recorded(p, os.path.join(args.build, "ictus"), SR, "ictus-sound-retune-")
    y = np.abs(y).max(axis=1)
    at = int(CHANGE * SR)
    before = y[at - 480:at].max()  # the last 10 ms before the change
    after = y[at:].max()
    check(rc == 0 and np.all(np.isfinite(y)) and after <= 1.05 * lower * before,
          "%s while ringing: peak after %.4g, the last 10 ms before %.4g (bound x%.2f)"
          % (change, after, before, 1.05 * lower))
if failed():
    raise SystemExit(1)
print("ok")
