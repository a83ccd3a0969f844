"""A value exactly at a documented limit is taken without a word, in a message and
as a creation argument, for every one-number parameter of membrane~ and contact~.

A Pd message carries a 32-bit float: 0.01 arrives as 0.0099999998 and 1e-4 as
9.99999975e-05, below the double limits the core compares with, and used to get
"must be in [...]" for the limit itself. The mass's limits (the density's times
pi a^2) are not round: typed as the error line quotes them (%g) or in full, they
are the limit too. The limits are written out here from docs/externals.md; the
mass's are computed here. A value one step further out still gets its error line."""
import argparse
import math
import os

from ictus_tools.checks import check
from ictus_tools.pdrun import make_workdir, Patch, error_lines, run_pd

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
args.build = os.path.abspath(args.build)

# docs/externals.md: (message, min, max)
membrane_limits = [("radius", 0.01, 2.0), ("tension", 1.0, 1e5), ("density", 0.01, 20.0),
                   ("modes", 1, 4096), ("t60", 0.005, 60.0), ("hfdamp", 0.0, 1000.0),
                   ("gain", -1e6, 1e6), ("openness", 0.0, 1.0), ("edgedamp", 0.0, 1e4),
                   ("cascade", 0.0, 100.0), ("vonkarman", 0.0, 10.0)]
contact_limits = [("mass", 1e-4, 10.0), ("stiffness", 1.0, 1e12), ("alpha", 1.0, 4.0),
                  ("damping", 0.0, 1e13)]


def texts(value):
    """The ways a user writes a limit: as the docs and error lines print it (%g)
    and in full (as many digits as a double has)."""
    return sorted({"%g" % value, "%.17g" % value})


membrane_msgs, contact_msgs = [], []
for name, lo, hi in membrane_limits:
    for v in (lo, hi):
        membrane_msgs += ["%s %s" % (name, t) for t in texts(v)]
# The mass at radii where both limits, printed with %g, fall outside the range.
for radius in (0.15, 0.1, 0.3):
    area = math.pi * radius * radius
    membrane_msgs.append("radius %g" % radius)
    for v in (0.01 * area, 20.0 * area):
        membrane_msgs += ["mass %s" % t for t in texts(v)]
for name, lo, hi in contact_limits:
    for v in (lo, hi):
        contact_msgs += ["%s %s" % (name, t) for t in texts(v)]

sr = 48000
work = make_workdir("ictus-limits-")
p = Patch(declare="-path %s/ictus" % args.build)
# Creation arguments at the limits (radius tension density modes); both heads ring.
lo_head = p.obj("membrane~ lim-lo 0.01 1 0.01 1")
hi_head = p.obj("membrane~ lim-hi 2 100000 20 4096")
mem = p.obj("membrane~ lim-drum")
con = p.obj("contact~ lim-drum")
lb = p.obj("loadbang")
steps = p.obj("t b b b b b")  # right to left: the limits, read-back, one step past, quit
p.connect(lb, 0, steps, 0)
for target, msgs in ((mem, membrane_msgs), (con, contact_msgs)):
    m = p.msg(" \\, ".join(msgs))
    p.connect(steps, 4, m, 0)
    p.connect(m, 0, target, 0)
for head in (lo_head, hi_head):
    pr = p.msg("print")
    p.connect(steps, 3, pr, 0)
    p.connect(pr, 0, head, 0)
readback = p.msg("tension 1 \\, radius 0.01 \\, density 0.01 \\, t60 0.005 \\, print")
p.connect(steps, 2, readback, 0)
p.connect(readback, 0, mem, 0)
# One value just past each kind of limit must still be refused.
past = p.msg("radius 0.0099 \\, density 20.001")
p.connect(steps, 1, past, 0)
p.connect(past, 0, mem, 0)
past_c = p.msg("mass 9.99e-05")
p.connect(steps, 1, past_c, 0)
p.connect(past_c, 0, con, 0)
quit_msg = p.msg("\\; pd quit")
p.connect(steps, 0, quit_msg, 0)
rc, log = run_pd(p.text(), args.build, sr=sr, workdir=work)
print(log)
check(rc == 0, "pd exited cleanly")
expected = ["membrane~: radius must be in [0.01, 2] m, got 0.0099; using 0.01",
            "membrane~: density must be in [0.01, 20] kg/m^2, got 20.001; using 20",
            "contact~: mass must be in [0.0001, 10] kg, got 9.99e-05; using 0.0001"]
for e in expected:
    check(e in log, "one step past the limit is still refused: '%s'" % e)
unexpected = [l for l in error_lines(log) if not any(e in l for e in expected)]
check(not unexpected, "%d limits in messages, 8 in creation arguments: no error line%s"
      % (len(membrane_msgs) + len(contact_msgs),
         "" if not unexpected else ": " + " | ".join(unexpected)))
check("membrane~ lim-lo: radius 0.01 m, tension 1 N/m, density 0.01 kg/m^2" in log
      and ", 1 modes," in log, "lim-lo uses radius, tension, density and modes at their minimum")
check("membrane~ lim-hi: radius 2 m, tension 100000 N/m, density 20 kg/m^2" in log
      and ", 4096 modes," in log, "lim-hi uses them at their maximum")
check("membrane~ lim-drum: radius 0.01 m, tension 1 N/m, density 0.01 kg/m^2" in log
      and "t60 0.005 s" in log, "lim-drum reads back radius, density and t60 at their minimum")
