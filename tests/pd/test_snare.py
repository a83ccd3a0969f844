"""The snare preset in the real pd binary: a mezzo-forte stroke (a 50 g wood stick at
2.5 m/s through contact~, r/a 0.3) on membrane~ "preset snare" (batter, snare head, the
shell's air, wires), wires on and off. The wires collide with the snare head (on and
off differ within 5 ms of the stroke), they raise the bandwidth holding 95 % of the
energy of the first 50 ms, the output stays finite, and a bad "wires" argument (or wires on
a cymbal) is an error naming the object. The bandwidths are printed (docs/sound.md records them; the
acceptance asks >= 4 kHz with the wires at mf, which this 50 g stroke does not reach and the
performer's strokes reach only at the edge, scripts/snare_render.py; a recorded snare reaches
8.2-8.6 kHz).

95 % bandwidth: the frequency below which the periodogram (rectangular window, the
50 ms from the stroke's first sample) holds 95 % of the energy."""
import argparse
import os

import numpy as np

from ictus_tools.checks import check
from ictus_tools.pdrun import make_workdir, Patch, error_lines, read_wav_float, recorder, run_pd

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
ap.add_argument("--velocity", type=float, default=2.5)
args = ap.parse_args()
args.build = os.path.abspath(args.build)

sr = 48000
seconds = 0.5
work = make_workdir("ictus-snare-")
wav = os.path.join(work, "snare.wav")
p = Patch(declare="-path %s/ictus" % args.build)
on = p.obj("membrane~ on")
off = p.obj("membrane~ off")
stick_on = p.obj("contact~ on")
stick_off = p.obj("contact~ off")
trig = recorder(p, [(on, 0, "on"), (off, 0, "off")], seconds, sr, wav)
set_on = p.msg("preset snare")
set_off = p.msg("preset snare \\, wires off \\, wires maybe")
plate = p.obj("membrane~ plate")
set_plate = p.msg("preset crash \\, wires on")
hit = p.msg("hit %g 0.3 0 0.05" % args.velocity)
p.connect(trig, 1, set_on, 0)
p.connect(set_on, 0, on, 0)
p.connect(trig, 1, set_off, 0)
p.connect(set_off, 0, off, 0)
p.connect(trig, 1, set_plate, 0)
p.connect(set_plate, 0, plate, 0)
p.connect(trig, 1, hit, 0)
p.connect(hit, 0, stick_on, 0)
p.connect(hit, 0, stick_off, 0)
rc, log = run_pd(p.text(), args.build, sr=sr, workdir=work)
print(log)
check(rc == 0, "pd exited cleanly")
errors = error_lines(log)
check(len(errors) == 2 and any("membrane~ off: wires: expected on or off" in e for e in errors)
      and any("membrane~ plate: wires: a cymbal (a plate) has no snare wires" in e
              for e in errors),
      "two errors, for 'wires maybe' and for wires on a cymbal, naming the objects: %s" % errors)
x, wsr = read_wav_float(wav)
check(np.all(np.isfinite(x)), "output finite")


def bandwidth95(y):
    """Frequency (Hz) below which 95 % of the energy of the first 50 ms lies."""
    nz = np.flatnonzero(np.abs(y) > 0)
    start = nz[0] if len(nz) else 0
    seg = y[start:start + int(0.05 * sr)].astype(np.float64)
    power = np.abs(np.fft.rfft(seg)) ** 2
    cum = np.cumsum(power) / np.sum(power)
    freqs = np.fft.rfftfreq(len(seg), 1.0 / sr)
    above = np.sum(power[freqs >= 4000.0]) / np.sum(power)
    return freqs[np.searchsorted(cum, 0.95)], np.sqrt(np.mean(seg ** 2)), above


bw_on, rms_on, hf_on = bandwidth95(x[:, 0])
bw_off, rms_off, hf_off = bandwidth95(x[:, 1])
print("95 %% bandwidth: wires on %.0f Hz (rms %.3g, %.2f %% of the energy above 4 kHz), "
      "off %.0f Hz (rms %.3g, %.3f %% above 4 kHz)"
      % (bw_on, rms_on, 100.0 * hf_on, bw_off, rms_off, 100.0 * hf_off))
check(rms_on > 0 and rms_off > 0, "both sound")
check(bw_off < bw_on, "the wires raise the 95 %% bandwidth (%.0f Hz off, %.0f Hz on)" % (bw_off, bw_on))
first = np.flatnonzero(np.abs(x[:, 1]) > 0)[0]
differ = np.flatnonzero(x[:, 0] != x[:, 1])
check(len(differ) > 0 and differ[0] < first + int(0.005 * sr),
      "the wires change the sound within 5 ms of the stroke (first difference %.2f ms in)"
      % (1000.0 * (differ[0] - first) / sr if len(differ) else -1))
