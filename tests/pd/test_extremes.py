"""The tester's report: every parameter of membrane~ and contact~ set out of range
(clamped to its limit with an error line), then a hit, peaked at 2.5e4 and more
(1e13 at 96 kHz). The contact solve, with a 10 kg stick, stiffness 1e12 and damping
1e13 on a 1 cm head of 0.01 kg/m^2, stopped far from its root and fed the head
forces of 1e7 N. Now the output must stay below the bound of docs/externals.md
("Output bound"): the contact is passive, the head holds at most the stick's
m v^2 / 2, and a pickup reads at most

    |gain| * ||psi(pickup)|| * v * sqrt(m / (sigma a^2)),

||psi||^2 the sum of the squared mass-normalised mode shapes at the pickup over the
modes that ring, computed here from scipy's Bessel zeros (not by the code under test)."""
import argparse
import math
import os

import numpy as np
from scipy.special import jn_zeros, jv

from ictus_tools.checks import check
from ictus_tools.pdrun import make_workdir, Patch, read_wav_float, recorder, run_pd

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
args.build = os.path.abspath(args.build)

sr = 96000
radius, tension, density, modes = 0.01, 1.0, 0.01, 128   # the limits the values clamp to
stick_mass, velocity, gain = 10.0, 50.0, 0.16


def shape_norm(r, theta_deg, count, j_cut):
    """||psi|| at (r/a, theta) over the first `count` modes below j_cut."""
    table = []
    for m in range(0, 40):
        for j in jn_zeros(m, 20):
            table += [(j, m, s) for s in ((0,) if m == 0 else (0, 1))]
    table.sort()
    th = math.radians(theta_deg)
    total = 0.0
    for j, m, s in table[:count]:
        if j >= j_cut:
            break
        norm = math.sqrt((1.0 if m == 0 else 2.0) / math.pi) / abs(jv(m + 1, j))
        psi = jv(m, j * r) * (math.sin(m * th) if s else math.cos(m * th)) * norm
        total += psi * psi
    return math.sqrt(total)


c = math.sqrt(tension / density)
j_cut = 0.95 * 0.5 * sr * 2.0 * math.pi * radius / c
psi = max(shape_norm(0.5, 0.0, modes, j_cut), shape_norm(0.5, 90.0, modes, j_cut))
bound = gain * psi * velocity * math.sqrt(stick_mass / (density * radius * radius))

work = make_workdir("ictus-extremes-")
wav = os.path.join(work, "extremes.wav")
p = Patch(declare="-path %s/ictus" % args.build)
mem = p.obj("membrane~ extreme-drum 0 0 0")          # radius, tension, density -> minimum
con = p.obj("contact~ extreme-drum")
trig = recorder(p, [(mem, 0, "left"), (mem, 1, "right"), (con, 0, "force")], 0.3, sr, wav)
setup_m = p.msg("t60 1000 \\, hfdamp -1")             # 60 s, 0: the least loss
setup_c = p.msg("mass 1000 \\, stiffness 1e+20 \\, alpha 0 \\, damping 1e+20")
for msg, target in ((setup_m, mem), (setup_c, con)):
    p.connect(trig, 1, msg, 0)
    p.connect(msg, 0, target, 0)
d = p.obj("delay 10")
hit = p.msg("hit 1e+09 0.3 0")                        # velocity -> 50 m/s
p.connect(trig, 0, d, 0)
p.connect(d, 0, hit, 0)
p.connect(hit, 0, con, 0)
rc, log = run_pd(p.text(), args.build, sr=sr, workdir=work)
print(log)
check(rc == 0, "pd exited cleanly")
for expect in ["radius must be in [0.01, 2] m, got 0; using 0.01",
               "tension must be in [1, 100000] N/m, got 0; using 1",
               "density must be in [0.01, 20] kg/m^2, got 0; using 0.01",
               "mass must be in [0.0001, 10] kg, got 1000; using 10",
               "stiffness must be in [1, 1e+12] N/m^alpha, got 1e+20; using 1e+12",
               "alpha must be in [1, 4], got 0; using 1",
               "damping must be in [0, 1e+13] N s/m^(alpha+1), got 1e+20; using 1e+13",
               "hit: velocity must be in (0, 50] m/s, got 1e+09; using 50"]:
    check(expect in log, "clamped: '%s'" % expect)
x, _ = read_wav_float(wav)
check(np.all(np.isfinite(x)), "output finite")
peak = float(np.max(np.abs(x[:, :2])))
check(np.max(x[:, 2]) > 0, "the stick touched the head (peak force %g N)" % np.max(x[:, 2]))
check(peak <= bound * (1 + 1e-3), "peak %g below the output bound %g (||psi|| %g)" % (peak, bound, psi))
