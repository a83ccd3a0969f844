"""[ictus-kit] fed strike lists too short to name a drum (docs/pd-osc.md, "[ictus-kit]"): the
drum is the 8th number of ictus-receive's strike list, and a list of 4..7 numbers (what
[ictus-drum] and the sound models take, typed by hand) has none, so it is drum 0's: it
leaves by the left outlet, whichever drum the strike before it played. In batch pd: kit
drum 2 on, a full strike on drum 2, then short lists; each must come out of the left outlet
as it went in, and none may strike drum 2 again (the kit's signal outlets only decay).

    PYTHONPATH=python python3 tests/pdosc/test_kit_short.py --build build
"""
import argparse
import os

import numpy as np

from ictus_tools.checks import check
from ictus_tools.pdrun import Patch, error_lines, read_wav_float, recorder, run_pd, make_workdir

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
args.build = os.path.abspath(args.build)

SR = 48000


def full(drum):
    """ictus-receive's 19 numbers: hand 1, 3 m/s at r/a 0.3, drum `drum`, no stick tip."""
    return "1 3 0.3 0 0.05 100 0 %d 1 0.1 0 0 0 0.01 1 0 0 1 0" % drum


SHORT = ["0 3 0.3 0", "1 2 0.4 10 0.05", "0 2 0.5 20 0.05 80", "1 2 0.6 30 0.05 80 0"]
# (ms, message, inlet): drum 2 on, struck at 50 ms, then each short list after a drum 2 strike
EVENTS = [(1, "drum 2 tom tom 0.2 3000 0 45", 1)]
for i, s in enumerate(SHORT):
    EVENTS += [(50 + 200 * i, full(2), 0), (150 + 200 * i, s, 0)]
SECONDS = (EVENTS[-1][0] + 100) / 1000.0

work = make_workdir("ictus-kit-short-")
wav = os.path.join(work, "kit.wav")
p = Patch(declare="-path %s/ictus" % args.build)
kit = p.obj("ictus-kit")
pr = p.obj("print drum0")
p.connect(kit, 0, pr, 0)
trig = recorder(p, [(kit, 1, "left"), (kit, 2, "right")], SECONDS, SR, wav)
for ms, text, inlet in EVENTS:
    dl, mm = p.obj("delay %g" % ms), p.msg(text)
    p.connect(trig, 0, dl, 0)
    p.connect(dl, 0, mm, 0)
    p.connect(mm, 0, kit, inlet)
rc, log = run_pd(p.text(), args.build, sr=SR, workdir=work)
check(rc == 0 and not error_lines(log), "pd ran cleanly")
out = [line[len("drum0: "):].strip() for line in log.splitlines() if line.startswith("drum0: ")]
check(out == SHORT, "every short list leaves by the left outlet as drum 0's: %s" % out)

x, _ = read_wav_float(wav)
kit_out = np.max(np.abs(x.astype(np.float64)), axis=1)
for i, s in enumerate(SHORT):
    hit, short = (50 + 200 * i) * SR // 1000, (150 + 200 * i) * SR // 1000
    attack = np.max(kit_out[hit:hit + 480])
    before = np.max(kit_out[short - 480:short])
    after = np.max(kit_out[short:short + 480])
    check(attack > 0.05, "the drum 2 strike sounds on the kit outlets (peak %.3g)" % attack)
    check(after <= before, "'%s' does not strike drum 2: the 10 ms after it peak %.3g, "
          "the 10 ms before %.3g" % (s, after, before))
