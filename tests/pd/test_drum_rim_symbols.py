"""[ictus-drum]'s `rim <hand> <velocity> <r/a> <theta> [<stick_mass>]` with a symbol among its
numbers ('nan', 'inf' or a word for the velocity, r/a or theta): the stick's contact~ refuses the hit with its
own error line (naming contact~ and the argument), and the hoop, which the rim list also
drives, is silent for it without a word of its own: it unpacked the list as it came
("unpack: type mismatch", naming neither ictus-drum nor the argument) and rang on what
unpack let through. Seeded random lists; a good rim hit after them rings.

    PYTHONPATH=python python3 tests/pd/test_drum_rim_symbols.py --build build
"""
import argparse
import os
import random

import numpy as np

from ictus_tools.checks import check, keep_going, failed
from ictus_tools.pdrun import Patch, error_lines, recorder, run_recorded

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
args.build = os.path.abspath(args.build)
SR = 48000
LIB = os.path.join(args.build, "ictus")
rng = random.Random(20261202)

keep_going()
bad = []
for _ in range(6):
    atoms = [str(rng.randint(0, 1)), "%g" % round(rng.uniform(0.5, 8), 2),
             "%g" % round(rng.uniform(0.6, 1.0), 3), "%g" % round(rng.uniform(0, 360), 1)]
    if rng.random() < 0.5:
        atoms.append("%g" % round(rng.uniform(0.01, 0.1), 3))
    atoms[rng.randrange(1, 4)] = rng.choice(["nan", "inf", "foo", "-nan"])
    bad.append("rim " + " ".join(atoms))
p = Patch()
drum = p.obj("ictus-drum")
trig = recorder(p, [(drum, 0, "a"), (drum, 1, "b")], 0.5, SR, "WAV")
for ms, text in [(5 + 40 * k, text) for k, text in enumerate(bad)] + [(300.0, "rim 1 3 0.9 0")]:
    d = p.obj("delay %g" % ms)
    m = p.msg(text)
    p.connect(trig, 0, d, 0)
    p.connect(d, 0, m, 0)
    p.connect(m, 0, drum, 0)
rc, log, y = run_recorded(p, LIB, SR, "ictus-rim-symbols-")
errors = error_lines(log)
check(rc == 0 and y is not None and np.all(np.isfinite(y)), "pd ran, finite")
foreign = [e for e in errors if not e.startswith("error: contact~: hit: ")]
check(not foreign, "every error line is contact~'s refusal of the hit: others %s" % foreign[:3])
check(len(errors) == len(bad), "one error line per bad rim list (%d for %d)"
      % (len(errors), len(bad)))
if y is not None:
    at = int(0.3 * SR)
    before, after = np.abs(y[:at]).max(), np.abs(y[at:]).max()
    check(before == 0 and after > 1e-3, "silent for the refused lists (peak %.3g), the good rim "
          "hit rings (%.3g)" % (before, after))
if failed():
    raise SystemExit(1)
print("ok")
