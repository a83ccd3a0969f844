"""[ictus-sound-panel]'s inlet given a control's message without a number (`radius foo`,
a bare `t60`) or a `model` without its index (help/ictus-sound-panel-help.pd: model <name>
<index>, ictus-sound's third outlet): an error line of the panel that names the control and
quotes what it got, and nothing is sent. They reached a [t f f] ("trigger: generic messages
can only be converted to 'b' or 'a'") and a [set $1( box ("$1: argument number out of
range"), naming neither the panel nor the control. Seeded random bad messages.

    PYTHONPATH=python python3 tests/ui/test_sound_panel_badinput.py --build build
"""
import argparse
import os
import random

from ictus_tools.checks import check, keep_going, failed
from ictus_tools.pdrun import (Patch, check_bad_messages, error_lines, run_pd, make_workdir,
                               send_each_ms)

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
args.build = os.path.abspath(args.build)
LIB = os.path.join(args.build, "ictus")

rng = random.Random(20261202)
BAD = []  # (message, start of its error line, end of it)
for control in rng.sample(["radius", "tension", "mass", "modes", "t60", "hfdamp", "volume"], 5):
    value = rng.choice(["foo", "nan", "inf", ""])
    BAD.append(("%s %s" % (control, value)).strip())
for _ in range(3):
    BAD.append(rng.choice(["model %s" % rng.choice(["clips", "synth", "modal", "foo"]),
                           "model %s %d" % (rng.choice(["clips", "synth", "modal"]),
                                            rng.choice([3, 7, -1])),
                           "model", "model modal %.2f" % rng.uniform(0.1, 1.9)]))

p = Patch(declare="-path %s" % LIB)
panel = p.obj("ictus-sound-panel")
out1, out2 = p.obj("print sent"), p.obj("print drum")
p.connect(panel, 0, out1, 0)
p.connect(panel, 1, out2, 0)
send_each_ms(p, panel, BAD)
rc, log = run_pd(p.text(), LIB, workdir=make_workdir("ictus-panel-bad-"))
keep_going()
errors = error_lines(log)
check(rc == 0, "pd ran (exit %d)" % rc)
check_bad_messages(errors, "ictus-sound-panel", BAD)
sent = [l for l in log.splitlines() if l.startswith(("sent:", "drum:"))]
check(not sent, "nothing sent for them: %s" % sent[:3])
if failed():
    raise SystemExit(1)
print("ok")
