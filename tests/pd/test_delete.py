"""Deleting membrane~ and contact~ in any order, while a stroke is in progress
and DSP runs, is safe: no crash (and, in the ASan build, no use-after-free), the
contact~ left behind reports the missing membrane~ and is silent, and a
membrane~ created again under the same name is found and played at the next DSP
sort. Objects are created and deleted by messages to their subpatches
([; pd-mem clear(, [; pd-mem obj ...(), as a live patch would."""
import argparse
import os

import numpy as np

from ictus_tools.checks import check
from ictus_tools.pdrun import make_workdir, Patch, read_wav_float, recorder, run_pd

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
args.build = os.path.abspath(args.build)

MEM = ("obj 10 10 membrane~ del-drum \\, obj 10 40 throw~ del-bus \\, connect 0 0 1 0"
       " \\, obj 200 10 r del-strike \\, connect 2 0 0 0")
CON = ("obj 10 10 contact~ del-drum \\, obj 10 40 throw~ del-force \\, connect 0 0 1 0"
       " \\, obj 100 40 print report \\, connect 0 1 2 0 \\, obj 200 10 r del-hit"
       " \\, connect 3 0 0 0")
# (time ms, message). A stroke lasts about 9 ms here (1 m/s on this head), so
# deletions 0.3 ms after a hit land inside it.
score = [
    (0.0, "\\; pd-mem %s \\; pd-con %s" % (MEM, CON)),
    (10.0, "\\; del-hit hit 1 0.3 0"),  # report 1
    (30.0, "\\; del-hit hit 1 0.3 0"),
    (30.3, "\\; pd-mem clear"),  # membrane~ first, mid-stroke
    (40.0, "\\; del-hit hit 1 0.3 0"),  # contact~ with no membrane~: refused
    (60.0, "\\; pd-mem %s" % MEM),  # a new membrane~ by the same name
    (80.0, "\\; del-hit hit 2 0.5 30"),  # report 2
    (100.0, "\\; del-hit hit 2 0.5 30"),
    (100.3, "\\; pd-con clear"),  # contact~ first, mid-stroke
    (110.0, "\\; del-strike strike 0.5 0 0.01"),
    (120.0, "\\; pd-con %s" % CON),
    (140.0, "\\; del-hit hit 1 0.2 0"),
    (140.3, "\\; pd-mem clear \\; pd-con clear"),  # both at once
    (160.0, "\\; pd-con %s \\; pd-mem %s" % (CON, MEM)),  # contact~ created first
    (180.0, "\\; del-hit hit 3 0.4 90"),  # report 3
]
sr = 48000
work = make_workdir("ictus-delete-")
wav = os.path.join(work, "delete.wav")
p = Patch(declare="-path %s/ictus" % args.build)
p.subpatch("mem", Patch())
p.subpatch("con", Patch())
bus = p.obj("catch~ del-bus")
force = p.obj("catch~ del-force")
trig = recorder(p, [(bus, 0, "sound"), (force, 0, "force")], 0.25, sr, wav)
for t, text in score:
    d = p.obj("delay %g" % t)
    m = p.msg(text)
    p.connect(trig, 0, d, 0)
    p.connect(d, 0, m, 0)
rc, log = run_pd(p.text(), args.build, sr=sr, workdir=work)
print(log)
check(rc == 0, "pd exited cleanly after the deletions (exit %d)" % rc)
check("contact~: no membrane~ named 'del-drum'" in log,
      "the orphaned contact~ reports the missing membrane~")
check("contact~: hit: no membrane~ named 'del-drum'; ignored" in log,
      "a hit with no membrane~ is refused with an error")
check(log.count("report:") == 3, "exactly the three completed strokes reported their release"
      " (%d reports)" % log.count("report:"))
x, _ = read_wav_float(wav)
check(np.all(np.isfinite(x)), "output finite")
def seg(ch, t0, t1):
    return np.max(np.abs(x[int(t0 * sr / 1000):int(t1 * sr / 1000), ch]))
check(seg(0, 30, 30.3) > 0, "the hit before the deletion sounds")
check(seg(1, 40, 80) == 0, "no force without a membrane~, and no stale stroke on the new one")
check(seg(1, 80, 90) > 0, "a membrane~ created again is found and played")
check(seg(0, 110, 120) > 0, "membrane~ sounds on after its contact~ was deleted")
check(seg(1, 180, 200) > 0, "contact~ created before its membrane~ plays it")
