"""[ictus-sound-synth] plays both hands' strokes when they land at the same logical time (a
chord of the score, two MIDI notes at one tick): its resonators are linear, so the chord must
sound as the sum of its two strokes played alone. It had one exciter ([vline~], low-pass and
weights) for both hands, and a [vline~] segment replaces those that start at the same time:
the second stroke of the chord took the first one's place, whatever their velocities (a 5 m/s
left hand and a 0.1 m/s right hand at once peaked at 0.009 where the left hand alone peaked at
0.28). Seeded random strokes (velocity, r/a, theta, the time in fractional ms, which hand comes
first in the message); a stroke of one hand alone, the other's alone and both at once are
rendered by the same patch (the noise of the exciter is the same sequence in each run)."""
import argparse
import os
import random

import numpy as np

from ictus_tools.checks import check, keep_going, failed
from ictus_tools.pdrun import Patch, recorder, run_recorded

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
args.build = os.path.abspath(args.build)
SR = 48000
LIB = os.path.join(args.build, "ictus")


def render(at_ms, strokes):
    """Both pickups of one ictus-sound-synth given `strokes` (lists) in one message at at_ms."""
    p = Patch()
    synth = p.obj("ictus-sound-synth")
    trig = recorder(p, [(synth, 0, "a"), (synth, 1, "b")], 0.25, SR, "WAV")
    d = p.obj("delay %.17g" % at_ms)
    m = p.msg(" \\, ".join(strokes))
    p.connect(trig, 0, d, 0)
    p.connect(d, 0, m, 0)
    p.connect(m, 0, synth, 0)
    rc, log, y = run_recorded(p, LIB, SR, "ictus-sound-chord-")
    check(rc == 0 and y is not None and np.all(np.isfinite(y)),
          "rendered %s: exit %d, finite output" % (strokes, rc))
    return y if y is not None else np.zeros((int(0.25 * SR), 2), np.float32)


keep_going()
rng = random.Random(20261202)
for case in range(5):
    at_ms = rng.uniform(10.0, 60.0)
    strokes = []
    for hand in (0, 1):
        velocity = 10 ** rng.uniform(np.log10(0.1), np.log10(10.0))
        strokes.append("%d %.6g %.4f %.3f" % (hand, velocity, rng.uniform(0.0, 0.95),
                                            rng.uniform(0.0, 360.0)))
    left = render(at_ms, [strokes[0]]).astype(np.float64)
    right = render(at_ms, [strokes[1]]).astype(np.float64)
    order = strokes if rng.random() < 0.5 else strokes[::-1]
    both = render(at_ms, order).astype(np.float64)
    expected = left + right
    scale = np.abs(expected).max()
    err = np.abs(both - expected).max()
    check(scale > 0 and err <= 1e-4 * scale,
          "chord %s at %.3f ms: the sum of its strokes alone (peak %.4g), max difference %.3g"
          % (order, at_ms, scale, err))
if failed():
    raise SystemExit(1)
print("ok")
