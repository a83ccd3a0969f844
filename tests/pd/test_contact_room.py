"""A membrane~ holds four coupling points (docs/externals.md): the contact~s, and the snare side
of `preset snare` (or `wires on`), which takes one. A contact~ refused for want of a point is
told why: with four contact~s, "already has 4 contact~s"; with three and the snare side, "no
free coupling point" naming the snare (it said "already has 4 contact~s" with three, found
writing a patch by hand). The three that fit play, the fourth is silent."""
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

keep_going()
p = Patch()
mem = p.obj("membrane~ room-drum")
preset = p.msg("preset snare")
lb = p.obj("loadbang")
p.connect(lb, 0, preset, 0)
p.connect(preset, 0, mem, 0)
contacts = []
for k in range(4):
    c = p.obj("contact~ room-drum")
    r = p.obj("r room-hit-%d" % k)
    p.connect(r, 0, c, 0)
    contacts.append(c)
trig = recorder(p, [(mem, 0, "out")], 0.5, SR, "WAV")
for k in range(4):
    d = p.obj("delay %g" % (50 + 100 * k))
    m = p.msg("\\; room-hit-%d hit 3 0.3 0" % k)
    p.connect(trig, 0, d, 0)
    p.connect(d, 0, m, 0)
rc, log, y = run_recorded(p, os.path.join(args.build, "ictus"), SR, "ictus-pd-room-")
check(rc == 0, "pd ran (rc %d)" % rc)
y = y[:, 0]
check("already has 4 contact~s" not in log,
      "three contact~s and the snare side: no line says four contact~s: %s" % log[-500:])
check("contact~: membrane~ 'room-drum' has no free coupling point: 3 contact~s and its snare "
      "side take the 4; this one is silent" in log, "the refusal names the snare side")
check("contact~: hit: membrane~ 'room-drum' has no free coupling point (its snare side takes "
      "one of the 4); this one is silent: ignored" in log, "... and so does the refused hit")
# Pd sorts the contact~s in its own order: three of the four hits sound, one does not
heard = []
for k in range(4):
    a = int((0.05 + 0.1 * k) * SR)
    before = np.abs(y[a - 960:a]).max()
    after = np.abs(y[a:a + 960]).max()
    heard.append(after > 2 * before + 1e-4)
check(sum(heard) == 3, "three hits sound, one is silent: %s" % heard)
if failed():
    raise SystemExit(1)
print("ok")
