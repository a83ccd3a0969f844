"""membrane~ "preset crash" in the real pd binary, struck once by contact~ (a 13.8 g
stick, wood tip, at r/a 0.9, pickup 1), with the preset's energy cascade and with
"cascade 0" (the linear plate), at pp (0.5 m/s) and ff (6 m/s; docs/gestures.md):

- ff, the acceptance: >= 10 % of the energy above 5 kHz (over 0-1 s and over 0-200
  ms), and the spectral centroid of 150-200 ms above that of 0-50 ms (it rises);
- ff, the linear plate: below 5 % above 5 kHz and a falling centroid (what the cascade
  changes, measured in the same run);
- pp: nearly linear: the cascade's part of the signal (|on - off|^2 / off^2 over 0-1 s)
  below 5 %, and below a third of ff's;
- every output finite; the cascade's render never louder than the linear one by more
  than its own energy allows: its energy over 0-1 s within 1.5 x the linear render's;
- "cascade" out of range: an error line naming membrane~ and cascade, clamped.

Spectra: 1024-sample Hann frames hopped by 256 (each sample weighs the same)."""
import argparse
import os

import numpy as np

from ictus_tools.checks import check, finish, keep_going
from ictus_tools.pdrun import make_workdir, Patch, read_wav_float, recorder, run_pd

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
args.build = os.path.abspath(args.build)

SR = 48000
work = make_workdir("ictus-crash-")
wav = os.path.join(work, "crash.wav")
p = Patch(declare="-path %s/ictus" % args.build)
runs = [("pp-on", 0.5, None), ("pp-off", 0.5, 0), ("ff-on", 6.0, None), ("ff-off", 6.0, 0)]
heads = [p.obj("membrane~ cr-%s" % n) for n, _, _ in runs]
trig = recorder(p, [(h, 0, n) for h, (n, _, _) in zip(heads, runs)], 1.2, SR, wav)
for (name, v, casc), head in zip(runs, heads):
    setup = p.msg("preset crash" + ("" if casc is None else " \\, cascade %g" % casc))
    stick = p.obj("contact~ cr-%s" % name)
    hit = p.msg("tip wood \\, hit %g 0.9 0 0.0138" % v)
    p.connect(trig, 1, setup, 0)
    p.connect(setup, 0, head, 0)
    p.connect(trig, 1, hit, 0)
    p.connect(hit, 0, stick, 0)
bad = p.obj("membrane~ cr-bad")
bad_msg = p.msg("preset crash \\, cascade -1 \\, cascade 500 \\, cascade nan")
p.connect(trig, 1, bad_msg, 0)
p.connect(bad_msg, 0, bad, 0)

rc, log = run_pd(p.text(), args.build, sr=SR, workdir=work)
print(log)
check(rc == 0, "pd exited cleanly")
keep_going()
x, _ = read_wav_float(wav)
check(np.all(np.isfinite(x)), "every output finite")
y = {n: x[:, i].astype(np.float64) for i, (n, _, _) in enumerate(runs)}


def spectrum(s, t0, t1, n=1024, hop=256):
    seg = np.concatenate([np.zeros(n), s[int(t0 * SR):int(t1 * SR)], np.zeros(n)])
    w = np.hanning(n)
    power = np.zeros(n // 2 + 1)
    for a in range(0, len(seg) - n + 1, hop):
        power += np.abs(np.fft.rfft(seg[a:a + n] * w)) ** 2
    return np.fft.rfftfreq(n, 1.0 / SR), power


def centroid(s, t0, t1):
    f, pw = spectrum(s, t0, t1)
    return np.sum(f * pw) / np.sum(pw)


def above(s, t0, t1, hz=5000.0):
    f, pw = spectrum(s, t0, t1)
    return np.sum(pw[f > hz]) / np.sum(pw)


def moved(on, off):
    return np.sum((on[:SR] - off[:SR]) ** 2) / np.sum(off[:SR] ** 2)


for n in y:
    print("%s: centroid 0-50 ms %.0f Hz, 150-200 ms %.0f Hz; above 5 kHz 0-200 ms %.1f %%, "
          "0-1 s %.1f %%" % (n, centroid(y[n], 0, 0.05), centroid(y[n], 0.15, 0.2),
                             100 * above(y[n], 0, 0.2), 100 * above(y[n], 0, 1.0)))
ff, lin = y["ff-on"], y["ff-off"]
check(above(ff, 0, 1.0) >= 0.10, "ff: %.1f %% of 0-1 s above 5 kHz >= 10 %%" % (100 * above(ff, 0, 1.0)))
check(above(ff, 0, 0.2) >= 0.10,
      "ff: %.1f %% of 0-200 ms above 5 kHz >= 10 %%" % (100 * above(ff, 0, 0.2)))
c0, c1 = centroid(ff, 0, 0.05), centroid(ff, 0.15, 0.2)
check(c1 > 1.2 * c0, "ff: the centroid rises, %.0f Hz (0-50 ms) to %.0f Hz (150-200 ms)" % (c0, c1))
check(above(lin, 0, 1.0) < 0.05 and centroid(lin, 0.15, 0.2) < centroid(lin, 0, 0.05),
      "ff, cascade 0: dark (%.1f %% above 5 kHz) and falling" % (100 * above(lin, 0, 1.0)))
m_pp, m_ff = moved(y["pp-on"], y["pp-off"]), moved(ff, lin)
check(m_pp < 0.05, "pp: the cascade moves %.3f of the signal (< 0.05): nearly linear" % m_pp)
check(m_pp < m_ff / 3.0, "pp moved %.3f < ff moved %.3f / 3" % (m_pp, m_ff))
e_on, e_off = np.sum(ff[:SR] ** 2), np.sum(lin[:SR] ** 2)
check(e_on < 1.5 * e_off, "ff: the cascade's render holds %.2f x the linear one's energy" % (e_on / e_off))
for value, used in (("-1", "0"), ("500", "100")):
    want = "membrane~: cascade must be in [0, 100], got %s; using %s" % (value, used)
    check(want in log, "error line: " + want)
check("membrane~: cascade: value must be a number, got 'nan'" in log, "a NaN cascade is refused")
finish()
