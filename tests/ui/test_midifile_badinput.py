"""[ictus-midifile] given `loop` or `open` with a value of the wrong kind (help/ictus-midifile-
help.pd: loop 0|1, open FILE): an error line of ictus-midifile that quotes it, and nothing
else complains. `loop foo` reached a [spigot]'s right inlet ("inlet: expected 'float' but
got 'foo'"), a bare `open` did nothing and said nothing, `open 5` was "no MIDI file list".
Seeded random values; a good `loop 1` and `open` of the example file among them say nothing.

    PYTHONPATH=python python3 tests/ui/test_midifile_badinput.py --build build
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
BAD = []  # (message, what the error line must end with)
for _ in range(4):
    word = rng.choice(["foo", "on", "yes", "nan"])
    BAD.append(("loop %s" % word, "got: %s" % word))
    number = rng.choice(["%d" % rng.randint(-5, 99), "%.3g" % rng.uniform(-10, 10)])
    BAD.append(("open %s" % number, "got: %s" % number))
BAD.append(("open", "got: bang"))
BAD.append(("loop", "got: bang"))
GOOD = ["loop 1", "loop 0", "open %s" % os.path.join(LIB, "ictus-midifile-example.mid")]

p = Patch(declare="-path %s" % LIB)
mf = p.obj("ictus-midifile")
messages = [text for text, _ in BAD] + GOOD
rng.shuffle(messages)
send_each_ms(p, mf, messages)
rc, log = run_pd(p.text(), LIB, workdir=make_workdir("ictus-midifile-bad-"))
keep_going()
errors = error_lines(log)
check(rc == 0, "pd ran (exit %d)" % rc)
check_bad_messages(errors, "ictus-midifile", [text for text, _ in BAD])
check(len(errors) == len(BAD), "one error line per bad message, none for %s (%d for %d)"
      % (GOOD, len(errors), len(BAD)))
if failed():
    raise SystemExit(1)
print("ok")
