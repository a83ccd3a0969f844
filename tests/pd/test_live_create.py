"""A contact~ created while DSP runs, with nothing on its signal outlet, plays at once: the way
a live patch grows, a [contact~ NAME] typed in with a message box into it and no cable to its
force outlet. Pd re-sorts DSP for a new object only when a signal connection is made, so such a
contact~ never ran its dsp method and never attached: every hit went to a stick nobody solved,
with no word (found writing a patch by hand). Now a hit that finds its membrane~ while the
contact~ is not attached, with DSP on, asks for the DSP sort first.

Checked: a contact~ created at 20 ms and hit at 40 ms sounds from the hit's block on (the sort
re-anchors the membrane~'s clock, so that first hit lands on a block's start, not later), and
reports the stroke; one created and hit in the same message sounds; one deleted mid-stroke and
created again plays its next hit; a fifth contact~ on a membrane~ with four is refused by name
as before."""
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
CON = "obj 10 10 contact~ live-drum \\, obj 10 40 print report \\, connect 0 1 1 0" \
      " \\, obj 200 10 r live-hit \\, connect 2 0 0 0"


def render(score, seconds=0.4, extra_contacts=0):
    p = Patch()
    mem = p.obj("membrane~ live-drum")
    for i in range(extra_contacts):
        p.obj("contact~ live-drum")
    sub = Patch()
    p.subpatch("con", sub)
    trig = recorder(p, [(mem, 0, "out")], seconds, SR, "WAV")
    for ms, text in score:
        d = p.obj("delay %g" % ms)
        m = p.msg(text)
        p.connect(trig, 0, d, 0)
        p.connect(d, 0, m, 0)
    rc, log, y = run_recorded(p, os.path.join(args.build, "ictus"), SR, "ictus-pd-live-")
    check(rc == 0, "pd ran (rc %d)" % rc)
    return y[:, 0], log


def onset(y):
    nz = np.nonzero(np.abs(y) > 1e-6)[0]
    return nz[0] if len(nz) else None


keep_going()
y, log = render([(20.0, "\\; pd-con %s" % CON), (40.0, "\\; live-hit hit 3 0.3 0")])
at = onset(y)
want = int(round(0.040 * SR))
check(at is not None and want - 64 <= at <= want + 1,
      "a contact~ created with DSP on plays its first hit: onset at %s, the hit at %d"
      % (at, want))
check(np.abs(y).max() > 0.05, "... and it sounds (peak %.3g)" % np.abs(y).max())
check("report:" in log, "... and reports the stroke: %s" % log[-300:])

y, log = render([(20.0, "\\; pd-con %s \\; live-hit hit 3 0.3 0" % CON)])
check(np.abs(y).max() > 0.05 and onset(y) <= int(round(0.020 * SR)) + 1,
      "created and hit in one message: sounds (peak %.3g, onset %s)"
      % (np.abs(y).max(), onset(y)))

y, log = render([(0.0, "\\; pd-con %s" % CON), (10.0, "\\; live-hit hit 0.5 0.3 0 0.5"),
                 (12.0, "\\; pd-con clear"), (100.0, "\\; pd-con %s" % CON),
                 (200.0, "\\; live-hit hit 3 0.3 0")])
late = y[int(0.19 * SR):int(0.2 * SR)]
after = y[int(0.2 * SR):int(0.23 * SR)]
check(np.abs(after).max() > 10 * max(np.abs(late).max(), 1e-6),
      "deleted mid-stroke and created again: the next hit sounds (%.3g after, %.3g before)"
      % (np.abs(after).max(), np.abs(late).max()))

y, log = render([(20.0, "\\; pd-con %s" % CON), (40.0, "\\; live-hit hit 3 0.3 0")],
                extra_contacts=4)
check("contact~: hit: membrane~ 'live-drum' already has 4 contact~s" in log,
      "a fifth contact~ created live is refused by name at its hit: %s" % log[-400:])
check(np.abs(y).max() == 0, "... and is silent (peak %.3g)" % np.abs(y).max())
if failed():
    raise SystemExit(1)
print("ok")
