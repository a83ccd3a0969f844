"""membrane~ "preset hihat" in the real pd binary, struck by contact~ (a 13.8 g stick,
wood tip, 2 m/s, on the bow at r/a 0.7), its pedal set by "openness":

- the broadband T60 of each render, from the energy decay curve (Schroeder's backward
  integral, a line from -5 to -25 dB, extrapolated to -60 dB), against the acceptance:
  closed (openness 0) < 0.3 s, open (1) > 1 s, half (0.5) between them;
- the pedal closed and opened again by a [line] (openness every 5 ms) while the plate
  rings: the output stays finite, stays the open render's exactly until the pedal
  moves, and after the pedal closed holds less energy than the open render;
- openness out of range: an error line naming membrane~ and openness, clamped."""
import argparse
import os

import numpy as np

from ictus_tools.checks import check, finish, keep_going
from ictus_tools.decay import schroeder_t60
from ictus_tools.pdrun import make_workdir, Patch, read_wav_float, recorder, run_pd

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
args.build = os.path.abspath(args.build)

sr = 48000
seconds = 4.0
sweep_at = 0.3  # s: the pedal starts to close
work = make_workdir("ictus-hihat-")
wav = os.path.join(work, "hihat.wav")
p = Patch(declare="-path %s/ictus" % args.build)
names = ["closed", "half", "open", "sweep"]
heads = [p.obj("membrane~ hh-%s" % n) for n in names]
trig = recorder(p, [(h, 0, n) for h, n in zip(heads, names)], seconds, sr, wav)
for name, head, openness in zip(names, heads, (0.0, 0.5, 1.0, 1.0)):
    setup = p.msg("preset hihat \\, openness %g" % openness)
    stick = p.obj("contact~ hh-%s" % name)
    hit = p.msg("tip wood \\, hit 2 0.7 0 0.0138")
    p.connect(trig, 1, setup, 0)
    p.connect(setup, 0, head, 0)
    p.connect(trig, 1, hit, 0)
    p.connect(hit, 0, stick, 0)
# the pedal: at 0.3 s from open to closed in 100 ms, held 100 ms, open again in 100 ms
line = p.obj("line 1 5")
for at_ms, move in ((sweep_at * 1000.0, "0 100"), (sweep_at * 1000.0 + 200.0, "1 100")):
    delay = p.obj("delay %g" % at_ms)
    ramp = p.msg(move)
    p.connect(trig, 1, delay, 0)
    p.connect(delay, 0, ramp, 0)
    p.connect(ramp, 0, line, 0)
fmt = p.msg("openness \\$1")
p.connect(line, 0, fmt, 0)
p.connect(fmt, 0, heads[3], 0)
# bad values, on a membrane~ of their own
bad = p.obj("membrane~ hh-bad")
bad_msg = p.msg("preset hihat \\, openness 1.5 \\, openness -0.2 \\, openness nan")
p.connect(trig, 1, bad_msg, 0)
p.connect(bad_msg, 0, bad, 0)

rc, log = run_pd(p.text(), args.build, sr=sr, workdir=work)
print(log)
check(rc == 0, "pd exited cleanly")
keep_going()
x, _ = read_wav_float(wav)
check(np.all(np.isfinite(x)), "every output finite")
t60 = {n: schroeder_t60(x[:, i], sr) for i, n in enumerate(names[:3])}
print("T60 (Schroeder, T20 x 3): " + ", ".join("%s %s s" % (n, t60[n]) for n in names[:3]))
check(all(t60[n] is not None for n in names[:3]), "every render decays past -25 dB")
if all(t60[n] is not None for n in names[:3]):
    check(t60["closed"] < 0.3, "closed T60 %.3f s < 0.3 s" % t60["closed"])
    check(t60["open"] > 1.0, "open T60 %.3f s > 1 s" % t60["open"])
    check(t60["closed"] < t60["half"] < t60["open"],
          "half T60 %.3f s between closed and open" % t60["half"])
sweep, opened = x[:, 3], x[:, 2]
n0 = int(sweep_at * sr)
check(np.array_equal(sweep[:n0], opened[:n0]), "the sweep render is the open one until the pedal moves")
# after the pedal closed (0.4-0.5 s) the sweep holds far less energy than the open hat
a, b = int(0.45 * sr), int(0.5 * sr)
e_sweep, e_open = np.sum(sweep[a:b] ** 2), np.sum(opened[a:b] ** 2)
check(e_sweep < 0.5 * e_open, "closing damps: %.3g of the open hat's energy at 0.45-0.5 s" % (e_sweep / e_open))
step_ring = np.max(np.abs(np.diff(opened[n0 - 2400:n0])))
step_sweep = np.max(np.abs(np.diff(sweep[n0:int(0.6 * sr)])))
check(step_sweep <= step_ring * 1.01,
      "no sample step while the pedal moves larger than the ringing's own (%.3g vs %.3g)"
      % (step_sweep, step_ring))
for value, used in (("1.5", "1"), ("-0.2", "0")):
    want = "membrane~: openness must be in [0, 1], got %s; using %s" % (value, used)
    check(want in log, "error line: " + want)
check("membrane~: openness: value must be a number, got 'nan'" in log, "a NaN openness is refused")
finish()
