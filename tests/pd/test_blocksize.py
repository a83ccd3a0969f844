"""The sound of membrane~ played by contact~ (and a strike) does not depend on
Pd's block size: the same score rendered with both objects inside a [block~ 1],
[block~ 64] and [block~ 1024] subpatch gives the same output up to float
rounding, once the 960-sample reblocking delay of [block~ 1024] in a 64-sample
parent is taken out. Also rendered with contact~ created before membrane~
(Pd then sorts contact~ first: its force outlet lags one block, the sound must
not change)."""
import argparse
import os

import numpy as np

from ictus_tools.checks import check
from ictus_tools.pdrun import make_workdir, Patch, error_lines, read_wav_float, recorder, run_pd

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
args.build = os.path.abspath(args.build)

sr = 48000
seconds = 0.6
score = [  # (delay ms, message to contact~ or membrane~)
    (10.0, "c", "hit 2 0.3 0"),
    (97.3, "c", "hit 0.7 0.6 45"),
    (151.1, "m", "strike 0.5 120 0.005"),
    (233.37, "c", "hit 5 0.1 200"),
    (301.01, "c", "hit 1.2 0.8 10"),
]
work = make_workdir("ictus-block-")
renders = {}
for block, contact_first in ((1, False), (64, False), (1024, False), (64, True)):
    sub = Patch()
    inl = sub.obj("inlet")
    route = sub.obj("route c m")
    sub.connect(inl, 0, route, 0)
    if contact_first:
        con = sub.obj("contact~ drum")
        mem = sub.obj("membrane~ drum")
    else:
        mem = sub.obj("membrane~ drum")
        con = sub.obj("contact~ drum")
    sub.connect(route, 0, con, 0)
    sub.connect(route, 1, mem, 0)
    o1, o2, o3 = sub.obj("outlet~"), sub.obj("outlet~"), sub.obj("outlet~")
    sub.connect(mem, 0, o1, 0)
    sub.connect(mem, 1, o2, 0)
    sub.connect(con, 0, o3, 0)
    sub.obj("block~ %d" % block)
    p = Patch(declare="-path %s/ictus" % args.build)
    s = p.subpatch("drum", sub)
    wav = os.path.join(work, "block-%d-%d.wav" % (block, contact_first))
    trig = recorder(p, [(s, 0, "left"), (s, 1, "right"), (s, 2, "force")], seconds, sr, wav)
    for d, target, text in score:
        dl = p.obj("delay %.17g" % d)
        mm = p.msg("%s %s" % (target, text))
        p.connect(trig, 0, dl, 0)
        p.connect(dl, 0, mm, 0)
        p.connect(mm, 0, s, 0)
    rc, log = run_pd(p.text(), args.build, sr=sr, workdir=work)
    check(rc == 0 and not error_lines(log), "pd ran cleanly (block %d)" % block)
    x, _ = read_wav_float(wav)
    check(np.all(np.isfinite(x)), "finite output (block %d)" % block)
    latency = block - 64 if block > 64 else 0
    renders[(block, contact_first)] = (x[latency:].astype(np.float64), block)

# Pd 0.53 sorts these unconnected objects in reverse creation order, so contact~
# created first runs after membrane~: its force outlet is then on time.
ref = renders[(64, False)][0][:, :2]
force_ref = renders[(64, True)][0][:, 2]
onset = np.flatnonzero(force_ref)[0]
check(onset == int(round(score[0][0] * sr / 1000.0)),
      "the first hit's force starts on its sample (%d)" % onset)
check(np.min(force_ref) >= 0 and np.max(force_ref) > 1.0,
      "contact force is a push (>= 0), peak %.1f N" % np.max(force_ref))
peak = np.max(np.abs(ref))
check(peak > 1e-6, "the reference render is not silent (peak %g)" % peak)
for key, (both, block) in renders.items():
    name = "block %d%s" % (key[0], " contact~ first" if key[1] else "")
    x, force = both[:, :2], both[:, 2]
    n = min(len(x), len(ref))
    diff = np.max(np.abs(x[:n] - ref[:n]))
    # float32 output: rounding differences stay near 1e-7 of the peak
    check(diff <= 1e-5 * peak, "%s vs 64: sound max |diff| %.3g (peak %.3g)" % (name, diff, peak))
    # the force outlet: exact, or exactly one block late if Pd sorted contact~ first
    fits = [lag for lag in (0, block)
            if np.all(force[:lag] == 0)
            and np.max(np.abs(force[lag:n] - force_ref[:n - lag])) <= 1e-5 * np.max(force_ref)]
    check(len(fits) == 1, "%s: force outlet equals the contact force with a lag of %s samples"
          % (name, fits))
