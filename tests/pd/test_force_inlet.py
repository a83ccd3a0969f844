"""The signal inlet: a force (N) applied at the "position" point. A one-sample
force pulse of A newtons at sample k is an impulse of A / sr newton-seconds,
which the core applies exactly as a `strike` of that impulse at offset k
(docs/membrane.md: strikes enter as a force J/T over their sample). So a
membrane~ fed the pulse through its inlet and another struck by message at the
same point and sample must give the same output, up to float rounding. The
pulse comes from [tabplay~] of a table holding A at index k, started with DSP;
the strike from [delay k * 1000 / sr]."""
import argparse
import os

import numpy as np

from ictus_tools.checks import check
from ictus_tools.pdrun import make_workdir, Patch, error_lines, read_wav_float, recorder, run_pd

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
args.build = os.path.abspath(args.build)

sr = 48000
k = 1000  # sample of the pulse
force_n = 48.0  # one sample of 48 N at 48 kHz: 0.001 N s
point = "0.42 75"
work = make_workdir("ictus-inlet-")
wav = os.path.join(work, "inlet.wav")
p = Patch(declare="-path %s/ictus" % args.build)
by_signal = p.obj("membrane~")
by_message = p.obj("membrane~")
p.table("pulse", 2 * k)
play = p.obj("tabplay~ pulse")
p.connect(play, 0, by_signal, 0)
trig = recorder(p, [(by_signal, 0, "a"), (by_message, 0, "b"), (by_signal, 1, "c"),
                    (by_message, 1, "d")], 0.2, sr, wav)
setup = p.msg("\\; pulse %d %g" % (k, force_n))
pos = p.msg("position %s \\, pickup 2 0.8 200" % point)
p.connect(trig, 2, setup, 0)  # before DSP starts
p.connect(trig, 2, pos, 0)
p.connect(pos, 0, by_signal, 0)
pick = p.msg("pickup 2 0.8 200")
p.connect(trig, 2, pick, 0)
p.connect(pick, 0, by_message, 0)
p.connect(trig, 1, play, 0)  # starts with the first DSP block, like the recording
d = p.obj("delay %.17g" % (k * 1000.0 / sr))
strike = p.msg("strike %s %.17g" % (point, force_n / sr))
p.connect(trig, 0, d, 0)
p.connect(d, 0, strike, 0)
p.connect(strike, 0, by_message, 0)
rc, log = run_pd(p.text(), args.build, sr=sr, workdir=work)
check(rc == 0 and not error_lines(log), "pd ran cleanly")
x, _ = read_wav_float(wav)
x = x.astype(np.float64)
check(np.all(np.isfinite(x)), "finite output")
for sig, msg, name in ((0, 1, "pickup 1"), (2, 3, "pickup 2")):
    a, b = x[:, sig], x[:, msg]
    onset = np.flatnonzero(a)
    check(len(onset) > 0 and onset[0] == k, "%s: the force pulse sounds from sample %d (%s)"
          % (name, k, onset[:1]))
    peak = np.max(np.abs(b))
    diff = np.max(np.abs(a - b))
    check(peak > 0 and diff <= 1e-5 * peak,
          "%s: inlet force pulse == strike of A/sr N s: max |diff| %.3g (peak %.3g)"
          % (name, diff, peak))
