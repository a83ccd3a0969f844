"""[ictus-kit]'s kit inlet given bad messages (docs/pd-osc.md, "[ictus-kit]"): a drum index
outside 0..7 or not whole, a symbol for it, too few numbers, a symbol for a number (pan,
tension), a pedal index outside 1..7. Each gets an error line from the kit that names it
(`ictus-kit: ...` or, for a drum's own message, `ictus-kit-drum N: ...`; a head parameter
may be reported by the membrane~ it reaches) and is ignored: nothing else complains (they
used to give `render-kit-9: no such object`, `$render-kit-$1: not enough arguments
supplied`, `select: no method for 'nan'`, `clip: no method for 'symbol'`, which name
neither the kit nor the parameter), and a good drum message after them still plays.
Seeded random members of each kind of fault.

    PYTHONPATH=python python3 tests/pdosc/test_kit_badinput.py --build build
"""
import argparse
import os
import random

import numpy as np

from ictus_tools.checks import check, keep_going, failed
from ictus_tools.pdrun import Patch, error_lines, read_wav_float, recorder, run_pd, make_workdir

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
args.build = os.path.abspath(args.build)

SR = 48000
rng = random.Random(20261202)


def bad_index():
    return rng.choice(["8", "9", "-1", "%d" % rng.randint(10, 1000), "%.2f" % rng.uniform(0.1, 6.9),
                       "foo", "nan", "-%d" % rng.randint(2, 50)])


def number():
    return "%.3g" % rng.uniform(0.1, 1.0)


def bad_messages():
    """(message, the start and the end of the error line it must get): every kind of
    fault, seeded. The kit quotes what it refused after 'got: ' (bang: nothing)."""
    msgs = []

    def refused(text):
        word, _, rest = text.partition(" ")
        return (text, "error: ictus-kit: %s takes" % word, "got: " + (rest or "bang"))

    for _ in range(3):
        msgs.append(refused("drum %s tom tom 0.2 3000 0 45" % bad_index()))
        full = ["drum", str(rng.randint(1, 7)), "tom", "tom", "0.2", "3000", "0"]
        msgs.append(refused(" ".join(full[:rng.randint(1, 5)])))
        n = rng.randint(1, 7)
        which = rng.choice(["pan", "tension"])
        fields = {"pan": number(), "tension": "3000"}
        fields[which] = rng.choice(["foo", "nan", "inf"])
        msgs.append(("drum %d tom tom 0.2 %s %s 45" % (n, fields["tension"], fields["pan"]),
                     "error: ictus-kit-drum %d: %s must be a number" % (n, which),
                     "got: " + fields[which]))
        msgs.append(refused("pedal %s %s" % (rng.choice(["0", "8", "-2", "3.5", "foo", "77"]),
                                             number())))
        msgs.append(refused("pedal"))
    return msgs


keep_going()
BAD = bad_messages()
EVENTS = [(5 + 2 * i, text, 1) for i, (text, _, _) in enumerate(BAD)]
GOOD_AT = 5 + 2 * len(BAD) + 10
EVENTS += [(GOOD_AT, "drum 2 tom tom 0.2 3000 0 45", 1),
           (GOOD_AT + 20, "1 3 0.3 0 0.05 100 0 2 1 0.1 0 0 0 0.01 1 0 0 1 0", 0)]
SECONDS = (GOOD_AT + 200) / 1000.0

work = make_workdir("ictus-kit-bad-")
wav = os.path.join(work, "kit.wav")
p = Patch(declare="-path %s/ictus" % args.build)
kit = p.obj("ictus-kit")
trig = recorder(p, [(kit, 1, "left"), (kit, 2, "right")], SECONDS, SR, wav)
for ms, text, inlet in EVENTS:
    dl, mm = p.obj("delay %g" % ms), p.msg(text)
    p.connect(trig, 0, dl, 0)
    p.connect(dl, 0, mm, 0)
    p.connect(mm, 0, kit, inlet)
rc, log = run_pd(p.text(), args.build, sr=SR, workdir=work)
errors = error_lines(log)
check(rc == 0, "pd ran (exit %d)" % rc)
foreign = [e for e in errors
           if not e.startswith(("error: ictus-kit", "error: membrane~"))]
check(not foreign, "every error line names the kit (or the membrane~): others %s" % foreign[:4])
for text, start, end in BAD:
    said = [e for e in errors if e.startswith(start) and e.rstrip().endswith(end)]
    check(said, "'%s': an error line '%s ... %s'" % (text, start, end))
x, _ = read_wav_float(wav)
at = int((GOOD_AT + 20) * SR / 1000)
peak = np.max(np.abs(x[at:at + 4800].astype(np.float64)))
check(np.all(np.isfinite(x)) and peak > 0.02,
      "drum 2 set after them plays a strike (peak %.3g on the kit outlets)" % peak)
if failed():
    raise SystemExit(1)
print("ok")
