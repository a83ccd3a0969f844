"""A membrane~ whose modes all lie above Nyquist (the core keeps modes above
0.95 x Nyquist silent) says so once, naming itself, when a creation argument, a
message or the sample rate of a DSP start puts it there: not on every block, not
again while it stays there, again after it has rung and gone back.

The lowest mode's frequency, j_01 c / (2 pi a), c = sqrt(T / sigma), is computed
here with scipy's Bessel zero, not taken from the code under test. The sample-rate
case runs a membrane~ inside a subpatch downsampled by [block~ 64 1 0.125]: it is
created at 48 kHz, where it rings, and its DSP starts at 6 kHz, where it cannot."""
import argparse
import math
import os
import re

import numpy as np
from scipy.special import jn_zeros

from ictus_tools.checks import check
from ictus_tools.pdrun import make_workdir, Patch, error_lines, read_wav_float, recorder, run_pd


def schedule(patch, trig, target, steps):
    """Each (ms, text) of steps: a [delay ms] from trig's start, then the message to target."""
    for ms, text in steps:
        d = patch.obj("delay %g" % ms)
        m = patch.msg(text)
        patch.connect(trig, 0, d, 0)
        patch.connect(d, 0, m, 0)
        patch.connect(m, 0, target, 0)


ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
args.build = os.path.abspath(args.build)

J01 = jn_zeros(0, 1)[0]


def lowest_hz(radius, tension, density):
    return J01 * math.sqrt(tension / density) / (2.0 * math.pi * radius)


sr = 48000
work = make_workdir("ictus-silent-")
wav = os.path.join(work, "silent.wav")
p = Patch(declare="-path %s/ictus" % args.build)
# 1 cm, 1e5 N/m, 0.01 kg/m^2: the lowest mode at 121 kHz.
tiny = p.obj("membrane~ tiny 0.01 100000 0.01")
# Rings at 48 kHz (lowest mode 4.1 kHz), not at 6 kHz (modes ring below 2850 Hz).
sub = Patch()
sub.obj("block~ 64 1 0.125")
sub.obj("membrane~ slow 0.01 3000 0.262")
p.subpatch("down", sub)
trig = recorder(p, [(tiny, 0, "out")], 0.5, sr, wav)
# While DSP runs: still silent (no word), fewer modes (no word), ringing (no word),
# silent again (a word, with the new count), ringing again.
steps = [(50, "tension 90000"), (100, "modes 64"), (150, "tension 1"),
         (200, "strike 0.3 0 1e-05"), (300, "tension 100000"), (350, "tension 3000")]
schedule(p, trig, tiny, steps)
rc, log = run_pd(p.text(), args.build, sr=sr, workdir=work)
print(log)
check(rc == 0, "pd exited cleanly")
said = [l for l in log.splitlines() if "lie above Nyquist" in l]
check(len(said) == 3, "said 3 times in 0.5 s of DSP (%d)" % len(said))
check(all(l in error_lines(log) for l in said) and len(error_lines(log)) == 3,
      "as error lines (findable), and no other error line")

pattern = re.compile(r"membrane~ (\S+): all (\d+) modes lie above Nyquist \(lowest ([0-9.e+]+) Hz, "
                     r"modes ring below ([0-9.e+]+) Hz at sr ([0-9.e+]+) Hz\): silent; lower the "
                     r"tension, raise the density or enlarge the radius")
expect = [("tiny", 128, lowest_hz(0.01, 1e5, 0.01), sr),      # its creation arguments
          ("slow", 128, lowest_hz(0.01, 3000, 0.262), sr / 8),  # the DSP start at 6 kHz
          ("tiny", 64, lowest_hz(0.01, 1e5, 0.01), sr)]       # tension 100000 after ringing
found = []
for line in said:
    m = pattern.search(line)
    check(m is not None, "the message names the object, the count and the frequencies: %s" % line)
    found.append((m.group(1), int(m.group(2)), float(m.group(3)), float(m.group(4)),
                  float(m.group(5))))
for name, count, f, rate in expect:
    hit = [x for x in found if x[0] == name and x[1] == count and x[4] == rate
           and abs(x[2] / f - 1) < 1e-5 and abs(x[3] / (0.95 * rate / 2) - 1) < 1e-5]
    check(len(hit) == 1, "%s: %d modes, lowest %.6g Hz at sr %g Hz" % (name, count, f, rate))
check(found[0][0] == "tiny" and found[-1][0] == "tiny" and found[-1][1] == 64,
      "tiny said it at creation and after tension 100000, in that order")

x, _ = read_wav_float(wav)
y = x[:, 0]
t_strike, t_silent = int(0.2 * sr), int(0.3 * sr)
check(np.all(np.isfinite(y)), "output finite")
check(np.max(np.abs(y[:t_strike])) == 0, "silent until tension 1 and the strike")
check(np.max(np.abs(y[t_strike:t_silent])) > 0, "rings at tension 1")

# A plate (a cymbal preset): its modes follow its bending stiffness, not the tension, so the
# word says to lower the bending; the tension leaves it silent, the bending makes it ring.
work = make_workdir("ictus-silent-plate-")
wav = os.path.join(work, "plate.wav")
p = Patch(declare="-path %s/ictus" % args.build)
cym = p.obj("membrane~ cym")
trig = recorder(p, [(cym, 0, "out")], 0.3, sr, wav)
# 1 cm and 0.01 kg/m^2: the crash's lowest mode (16.7 Hz at 0.2286 m, 8.6 kg/m^2, f ~ 1 / a^2
# sqrt(D / rho h)) goes to 16.7 x (0.2286 / 0.01)^2 x sqrt(8.6 / 0.01) = 2.6e5 Hz; bending
# 0.001 (from 9.35) brings it to 2.6e5 x sqrt(0.001 / 9.35) = 2.6 kHz.
steps = [(1, "preset crash"), (2, "radius 0.01"), (3, "density 0.01"),
         (100, "tension 1"), (101, "strike 0.3 0 1e-05"),
         (200, "bending 0.001"), (201, "strike 0.3 0 1e-05")]
schedule(p, trig, cym, steps)
rc, log = run_pd(p.text(), args.build, sr=sr, workdir=work)
print(log)
check(rc == 0, "pd exited cleanly (plate)")
said = [l for l in log.splitlines() if "lie above Nyquist" in l]
check(len(said) == 1 and said[0] in error_lines(log), "the plate said it once, as an error line")
check(said[0].endswith("silent; lower the bending, raise the density or enlarge the radius"),
      "the plate's word names its bending, not the tension: %s" % said[0])
y = read_wav_float(wav)[0][:, 0]
check(np.all(np.isfinite(y)), "plate output finite")
check(np.max(np.abs(y[:int(0.2 * sr)])) == 0, "tension 1 leaves the plate silent, struck")
check(np.max(np.abs(y[int(0.2 * sr):])) > 0, "bending 0.001 makes it ring")
