"""The externals load in every supported way and in either order, and the two
objects find each other: [ictus/membrane~] with -path <build>, [declare -path
<build>/ictus], a patch beside the ictus folder with [declare -path ictus],
-lib ictus; contact~ created before or after membrane~ (whichever binary Pd
loads first, both classes exist once). Each patch plays a hit through contact~
and must print the stroke's release report (physically plausible) and no error
line."""
import argparse
import os

from ictus_tools.checks import check
from ictus_tools.pdrun import make_workdir, Patch, error_lines, run_pd

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
build = os.path.abspath(args.build)
lib = os.path.join(build, "ictus")


def play(declare, mem_name, con_name, contact_first, extra=(), beside_lib=False):
    p = Patch(declare=declare)
    if contact_first:
        con = p.obj("%s load-drum" % con_name)
        mem = p.obj("%s load-drum" % mem_name)
    else:
        mem = p.obj("%s load-drum" % mem_name)
        con = p.obj("%s load-drum" % con_name)
    rep = p.obj("print report")
    p.connect(con, 1, rep, 0)
    lb = p.obj("loadbang")
    on = p.msg("\\; pd dsp 1")
    hit = p.msg("hit 1 0.3 0")
    done = p.obj("delay 100")
    quit_msg = p.msg("\\; pd quit")
    p.connect(lb, 0, on, 0)
    p.connect(lb, 0, hit, 0)
    p.connect(hit, 0, con, 0)
    p.connect(lb, 0, done, 0)
    p.connect(done, 0, quit_msg, 0)
    # A patch beside the ictus/ folder is written into the build folder itself.
    work = build if beside_lib else make_workdir("ictus-load-")
    name = "ictus-load-test-%d.pd" % os.getpid()
    rc, log = run_pd(p.text(), build, extra_args=extra, workdir=work, name=name, timeout=60)
    if beside_lib:
        os.remove(os.path.join(work, name))
    what = "%s + %s, %s first, declare %s %s" % (mem_name, con_name,
                                                 "contact~" if contact_first else "membrane~",
                                                 declare, " ".join(extra))
    check(rc == 0 and not error_lines(log), "%s: loads without errors%s"
          % (what, "" if not error_lines(log) else ": " + " | ".join(error_lines(log))))
    reports = [l.split(":")[1].split() for l in log.splitlines() if l.startswith("report:")]
    check(len(reports) == 1, "%s: contact~ found the membrane~ and played it" % what)
    duration_ms, peak_n, rebound_mps = (float(v) for v in reports[0])
    # a 1 m/s hit: the stick cannot leave faster than it came (energy), the
    # stroke is short, the force pushes
    check(0 < duration_ms < 50 and peak_n > 0 and 0 <= rebound_mps <= 1.0,
          "%s: release report %s is physical" % (what, reports[0]))


for first in (False, True):
    play(None, "ictus/membrane~", "ictus/contact~", first)
    play("-path %s" % lib, "membrane~", "contact~", first)
    play("-path ictus", "membrane~", "contact~", first, beside_lib=True)
    play(None, "membrane~", "contact~", first, extra=["-lib", "ictus/ictus"])
    play("-path %s" % lib, "ictus/membrane~", "contact~", first)
    play("-path %s" % lib, "membrane~", "ictus/contact~", first)
