"""More than one event inside one DSP block: a [block~ 2048] subpatch (43 ms at 48 kHz)
holds several hits of one contact~ (a roll, a flam) and, in a burst, more strikes than a
64-sample block ever does. The sound must not depend on the block size (docs/externals.md,
"Timing"): the same seeded random score rendered in [block~ 64] and [block~ 2048] gives the
same samples, once the 1984-sample reblocking delay is taken out, and each contact~ reports
the same strokes (duration, peak force, rebound) in the same order. A contact~ kept one
pending hit: a second hit within the same block replaced the first before it landed (hits
15 ms apart at block~ 2048: the first of each pair never sounded, and was not reported);
membrane~ kept 64 pending strikes and dropped the rest of a block's without a word."""
import argparse
import os
import random

import numpy as np

from ictus_tools.checks import check, keep_going, failed
from ictus_tools.pdrun import make_workdir, Patch, read_wav_float, recorder, run_pd

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
args.build = os.path.abspath(args.build)

SR = 48000
SECONDS = 0.8
BIG = 2048
LAG = BIG - 64


def score_for(seed):
    """(ms, target, message): two sticks' rolls with gaps of 4..25 ms, and a burst of
    strikes 0.1..0.6 ms apart (more than 64 within one 2048-sample block)."""
    rng = random.Random(seed)
    score = []
    for stick in ("c0", "c1"):
        t = rng.uniform(20.0, 40.0)
        while t < 420.0:
            score.append((t, stick, "hit %.4g %.4f %.2f" % (10 ** rng.uniform(-0.3, 0.8),
                                                           rng.uniform(0.0, 0.9),
                                                           rng.uniform(0.0, 360.0))))
            t += rng.uniform(4.0, 25.0)
    t = rng.uniform(450.0, 470.0)
    for _ in range(rng.randint(90, 140)):
        score.append((t, "m", "strike %.4f %.2f %.3g" % (rng.uniform(0.0, 0.9),
                                                        rng.uniform(0.0, 360.0),
                                                        10 ** rng.uniform(-5, -3))))
        t += rng.uniform(0.1, 0.6)
    return score


def render(score, block):
    sub = Patch()
    inl = sub.obj("inlet")
    route = sub.obj("route c0 c1 m")
    sub.connect(inl, 0, route, 0)
    mem = sub.obj("membrane~ crowd")
    cons = [sub.obj("contact~ crowd"), sub.obj("contact~ crowd")]
    for i, con in enumerate(cons):
        sub.connect(route, i, con, 0)
        rep = sub.obj("print report-%d" % i)
        sub.connect(con, 1, rep, 0)
    sub.connect(route, 2, mem, 0)
    o1, o2 = sub.obj("outlet~"), sub.obj("outlet~")
    sub.connect(mem, 0, o1, 0)
    sub.connect(mem, 1, o2, 0)
    sub.obj("block~ %d" % block)
    p = Patch(declare="-path %s/ictus" % args.build)
    s = p.subpatch("drum", sub)
    work = make_workdir("ictus-crowd-")
    wav = os.path.join(work, "out.wav")
    trig = recorder(p, [(s, 0, "left"), (s, 1, "right")], SECONDS, SR, wav)
    for ms, target, text in score:
        d = p.obj("delay %.17g" % ms)
        m = p.msg("%s %s" % (target, text))
        p.connect(trig, 0, d, 0)
        p.connect(d, 0, m, 0)
        p.connect(m, 0, s, 0)
    rc, log = run_pd(p.text(), args.build, sr=SR, workdir=work)
    reports = [[l.split(":", 1)[1].split() for l in log.splitlines()
                if l.startswith("report-%d:" % i)] for i in range(2)]
    errors = [l for l in log.splitlines() if "error" in l]
    y = read_wav_float(wav)[0].astype(np.float64) if os.path.exists(wav) else None
    check(rc == 0 and y is not None and np.all(np.isfinite(y)) and not errors,
          "block~ %d: exit %d, finite output, no error (%s)" % (block, rc, errors[:2]))
    return y, reports


keep_going()
for seed in (11, 12, 13):
    score = score_for(seed)
    hits = sum(1 for _, target, _ in score if target != "m")
    ref, ref_reports = render(score, 64)
    big, big_reports = render(score, BIG)
    n = len(ref) - LAG
    a, b = ref[:n], big[LAG:LAG + n]
    scale = np.abs(a).max()
    err = np.abs(a - b).max()
    check(scale > 0 and err <= 1e-5 * scale,
          "seed %d, %d hits and %d strikes: block~ %d renders block~ 64's samples (peak %.4g, "
          "max difference %.3g)" % (seed, hits, len(score) - hits, BIG, scale, err))
    for i in range(2):
        check(len(ref_reports[i]) > 5 and big_reports[i] == ref_reports[i],
              "seed %d, stick %d: %d reports at block~ 64, the same %d at block~ %d"
              % (seed, i, len(ref_reports[i]), len(big_reports[i]), BIG))
if failed():
    raise SystemExit(1)
print("ok")
