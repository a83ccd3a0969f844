"""membrane~'s "preset NAME" in the real pd binary.

- timpani: the partials (1,1):(2,1):(3,1):(4,1) of a strike, measured by FFT peak
  picking on the output, lie within 2.5 % of 1 : 1.50 : 1.98 : 2.44 (T. D. Rossing,
  Science of Percussion Instruments, 2000: a kettle-loaded head). The ideal membrane's
  1 : 1.340 : 1.665 : 1.980 misses (2,1) and (3,1) by far more.
- paper after another preset renders the same samples as a fresh membrane~ made linear
  (tensionmod, radiation and lossfactor 0).
- An unknown name is an error that names membrane~ and lists the presets."""
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
seconds = 3.0
work = make_workdir("ictus-presets-")
wav = os.path.join(work, "presets.wav")
p = Patch(declare="-path %s/ictus" % args.build)
timp = p.obj("membrane~ timp")
fresh = p.obj("membrane~ fresh")
again = p.obj("membrane~ again")
trig = recorder(p, [(timp, 0, "timp"), (fresh, 0, "fresh"), (again, 0, "again")], seconds, sr, wav)
t_msg = p.msg("preset timpani \\, strike 0.75 0 0.01")
f_msg = p.msg("tensionmod 0 \\, radiation 0 \\, lossfactor 0 \\, patch 0 \\, strike 0.3 20 0.01")
a_msg = p.msg("preset timpani \\, preset paper \\, strike 0.3 20 0.01 \\, preset bongo")
for msg, obj in ((t_msg, timp), (f_msg, fresh), (a_msg, again)):
    p.connect(trig, 1, msg, 0)
    p.connect(msg, 0, obj, 0)
rc, log = run_pd(p.text(), args.build, sr=sr, workdir=work)
print(log)
check(rc == 0, "pd exited cleanly")
errors = error_lines(log)
check(len(errors) == 1 and "membrane~ again: preset: unknown 'bongo'" in errors[0]
      and all(n in errors[0]
              for n in ("paper", "snare", "tom", "floor-tom", "timpani", "frame", "kick")),
      "one error, naming the object and listing the presets: %s" % errors)
x, wsr = read_wav_float(wav)
check(wsr == sr and x.shape[0] == int(seconds * sr), "recorded %d samples" % x.shape[0])

# paper is the linear head: the same samples as a fresh membrane~ made linear.
check(np.max(np.abs(x[:, 1])) > 0 and np.array_equal(x[:, 1], x[:, 2]),
      "preset paper renders the linear fresh membrane~'s samples exactly (max |diff| %g)"
      % np.max(np.abs(x[:, 1] - x[:, 2])))

# timpani: peak picking. Hann window, zero-padded FFT, parabolic interpolation.
y = x[:, 0].astype(np.float64)
check(np.all(np.isfinite(y)) and np.max(np.abs(y)) > 0, "timpani output finite and not silent")
nfft = 1 << 20
spec = np.abs(np.fft.rfft(y * np.hanning(len(y)), nfft))
logspec = np.log(spec + 1e-300)
df = sr / nfft
freqs = np.arange(len(spec)) * df
# Local maxima within 50 dB of the strongest, below 1 kHz.
band = freqs < 1000
top = np.max(spec[band])
peaks = [k for k in range(2, int(1000 / df)) if spec[k] > spec[k - 1] and spec[k] >= spec[k + 1]
         and spec[k] > top * 10 ** (-50 / 20)]


def interp(k):
    a, b, c = logspec[k - 1], logspec[k], logspec[k + 1]
    return (k + 0.5 * (a - c) / (a - 2 * b + c)) * df


peak_f = np.array([interp(k) for k in peaks])
check(len(peak_f) >= 4, "%d spectral peaks below 1 kHz: %s" % (len(peak_f), np.round(peak_f, 1)))
# (1,1): the strongest peak between 90 and 130 Hz (the preset tunes it to 110 Hz, A2).
in_band = [k for k in peaks if 90 <= k * df <= 130]
check(bool(in_band), "a peak between 90 and 130 Hz")
f11 = interp(max(in_band, key=lambda k: spec[k]))
print("(1,1) at %.2f Hz" % f11)
for mode, ratio in (((2, 1), 1.50), ((3, 1), 1.98), ((4, 1), 2.44)):
    nearest = peak_f[np.argmin(np.abs(peak_f - ratio * f11))]
    measured = nearest / f11
    check(abs(measured / ratio - 1) <= 0.025,
          "(%d,%d)/(1,1): measured %.4f, Rossing %.2f, off %.2f %% <= 2.5 %%"
          % (mode[0], mode[1], measured, ratio, 100 * abs(measured / ratio - 1)))
