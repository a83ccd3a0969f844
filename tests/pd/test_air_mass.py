"""membrane~'s "airmass" in the real pd binary: the air's mass on the head's modes
(docs/membrane.md, "The air's mass").

A linear head (tensionmod, radiation, lossfactor and patch 0) with seeded radius, tension,
density and airmass is struck once; the partials (0,1), (1,1), (2,1) and (0,2), picked
from the output's spectrum, must ring at the ideal membrane's frequencies times
1 / sqrt(1 + beta g), beta = airmass rho_air a / sigma, within 0.1 %. g, the air's mass on
the mode over the mode's own per unit of rho_air a / sigma, is computed by a second route
(ictus_tools.air: the mode's Hankel transform by quadrature over the head, not the closed
Lommel form the core uses, then the baffled head's low-frequency radiation reactance). The
same head with airmass 0 rings at the ideal frequencies; and g j tends to 1 for a high mode
(an infinite membrane's mass rho_air / k per unit area), checked on (20,1)."""
import argparse
import math
import os
import random

import numpy as np
from scipy.special import jn_zeros

from ictus_tools.air import RHO_AIR, air_g
from ictus_tools.checks import check
from ictus_tools.pdrun import make_workdir, Patch, error_lines, read_wav_float, recorder, run_pd

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
ap.add_argument("--seed", type=int, default=7)
args = ap.parse_args()
args.build = os.path.abspath(args.build)
rng = random.Random(args.seed)

MODES = [(0, 1), (1, 1), (2, 1), (0, 2)]


heads = []
for name in ("a", "b"):
    heads.append({"name": name, "radius": rng.uniform(0.10, 0.33), "tension": rng.uniform(800, 5000),
                  "density": rng.uniform(0.15, 0.6), "air": rng.uniform(0.5, 3.0)})
sr = 48000
seconds = 3.0
work = make_workdir("ictus-air-mass-")
wav = os.path.join(work, "air.wav")
p = Patch(declare="-path %s/ictus" % args.build)
objs = []
for h in heads:
    for air in (h["air"], 0.0):
        o = p.obj("membrane~ air-%s-%g" % (h["name"], air))
        msg = p.msg("modes 64 \\, tensionmod 0 \\, radiation 0 \\, lossfactor 0 \\, patch 0 \\, "
                    "t60 2 \\, hfdamp 0 \\, radius %.6f \\, tension %.3f \\, density %.6f \\, "
                    "airmass %.6f \\, pickup 1 0.37 11 \\, strike 0.43 23 0.01"
                    % (h["radius"], h["tension"], h["density"], air))
        objs.append((o, msg, h, air))
trig = recorder(p, [(o, 0, "ch%d" % i) for i, (o, _, _, _) in enumerate(objs)], seconds, sr, wav)
for o, msg, _, _ in objs:
    p.connect(trig, 1, msg, 0)
    p.connect(msg, 0, o, 0)
rc, log = run_pd(p.text(), args.build, sr=sr, workdir=work)
check(rc == 0, "pd exited cleanly")
check(not error_lines(log), "no error in pd's log: %s" % error_lines(log))
x, wsr = read_wav_float(wav)
check(wsr == sr and x.shape[0] == int(seconds * sr), "recorded %d samples" % x.shape[0])

nfft = 1 << 21
df = sr / nfft
g = {mode: air_g(*mode) for mode in MODES}
print("g (the air's mass per unit of rho a / sigma): %s"
      % ", ".join("(%d,%d) %.4f" % (m, n, v) for (m, n), v in g.items()))
for i, (_, _, h, air) in enumerate(objs):
    y = x[:, i].astype(np.float64)
    check(np.all(np.isfinite(y)) and np.max(np.abs(y)) > 0, "%s airmass %g: finite, not silent"
          % (h["name"], air))
    spec = np.abs(np.fft.rfft(y * np.hanning(len(y)), nfft))
    logspec = np.log(spec + 1e-300)
    c = math.sqrt(h["tension"] / h["density"])
    beta = air * RHO_AIR * h["radius"] / h["density"]
    for (m, n) in MODES:
        want = jn_zeros(m, n)[-1] * c / (2.0 * math.pi * h["radius"]) / math.sqrt(1.0 + beta * g[(m, n)])
        lo, hi = int(0.97 * want / df), int(1.03 * want / df)
        k = lo + int(np.argmax(spec[lo:hi]))
        a, b, cc = logspec[k - 1], logspec[k], logspec[k + 1]
        got = (k + 0.5 * (a - cc) / (a - 2 * b + cc)) * df
        check(abs(got / want - 1.0) <= 1e-3,
              "head %s (a %.3f m, T %.0f N/m, sigma %.3f kg/m^2), airmass %.2f: (%d,%d) at "
              "%.2f Hz, expected %.2f Hz (beta g %.4f), off %.3f %%"
              % (h["name"], h["radius"], h["tension"], h["density"], air, m, n, got, want,
                 beta * g[(m, n)], 100.0 * abs(got / want - 1.0)))

# A high mode: g j -> 1, the infinite membrane's rho_air / k.
j20 = jn_zeros(20, 1)[-1]
g20 = air_g(20, 1)
check(abs(g20 * j20 - 1.0) <= 0.03, "(20,1): g j = %.4f, within 3 %% of 1" % (g20 * j20))
