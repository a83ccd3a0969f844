"""The signal models given a strike list with a symbol among its four numbers (a 'nan' or
'inf' typed or passed on, a word; after the hand, which a list begins with): [ictus-sound-clips] and [ictus-sound-synth], alone and
as models of [ictus-sound], say so with an error line of their own that quotes the list,
and play nothing for it; a good strike after it plays. They unpacked the list as it came
("unpack: type mismatch", naming neither the object nor the strike). So does the clips'
`gain` without a number ("trigger: generic messages can only be converted to 'b' or 'a'").
Seeded random lists, the symbol at a random place.

    PYTHONPATH=python python3 tests/sound/test_strike_symbols.py --build build
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
for box, model, name in (("ictus-sound-clips", None, "ictus-sound-clips"),
                         ("ictus-sound-synth", None, "ictus-sound-synth"),
                         ("ictus-sound clips", "clips", "ictus-sound-clips"),
                         ("ictus-sound synth", "synth", "ictus-sound-synth")):
    bad = []
    for _ in range(4):
        # written as Pd prints them back (%g)
        atoms = [str(rng.randint(0, 1)), "%g" % round(rng.uniform(0.5, 8), 2),
                 "%g" % round(rng.uniform(0, 0.9), 3), "%g" % round(rng.uniform(0, 360), 1)]
        atoms[rng.randrange(1, 4)] = rng.choice(["nan", "inf", "foo", "-nan"])
        bad.append(" ".join(atoms))
    extra = ["gain foo", "gain"] if name == "ictus-sound-clips" and model is None else []
    p = Patch()
    obj = p.obj(box)
    trig = recorder(p, [(obj, 0, "a"), (obj, 1, "b")], 0.4, SR, "WAV")
    events = [(5 + k, text) for k, text in enumerate(bad + extra)] + [(200.0, "1 3 0.3 0")]
    for ms, text in events:
        d = p.obj("delay %g" % ms)
        m = p.msg(text)
        p.connect(trig, 0, d, 0)
        p.connect(d, 0, m, 0)
        p.connect(m, 0, obj, 0)
    rc, log, y = run_recorded(p, LIB, SR, "ictus-strike-symbols-")
    errors = error_lines(log)
    check(rc == 0 and y is not None and np.all(np.isfinite(y)), "%s: pd ran, finite" % box)
    foreign = [e for e in errors if not e.startswith("error: %s: " % name)]
    check(not foreign, "%s: every error line names %s: others %s" % (box, name, foreign[:3]))
    for text in bad:
        said = [e for e in errors if e.startswith("error: %s: a strike list takes" % name)
                and e.rstrip().endswith("got: " + text)]
        check(said, "%s: '%s' refused with an error line quoting it" % (box, text))
    for text in extra:
        said = [e for e in errors if e.startswith("error: %s: gain" % name)
                and e.rstrip().endswith("got: " + (text.split(" ", 1)[1] if " " in text else "bang"))]
        check(said, "%s: '%s' refused with an error line quoting it" % (box, text))
    if y is not None:
        at = int(0.2 * SR)
        before = np.abs(y[:at]).max()
        after = np.abs(y[at:]).max()
        check(before == 0 and after > 0.01,
              "%s: silent for the refused lists (peak %.3g), the good strike plays (%.3g)"
              % (box, before, after))
if failed():
    raise SystemExit(1)
print("ok")
