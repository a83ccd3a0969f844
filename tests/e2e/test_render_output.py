"""patches/ictus-render.pd's output stage (docs/pd-osc.md, "Offline"), in the real
pd: the stereo mix, the output gain, the soft limiter, the sample formats and
the report it prints. Every expectation is computed here from other renders
of the same events, never from the patch's own numbers:

- render-mix pickups at -40 dB (all linear) gives the drum's two pickups p1, p2;
  render-mix stereo at -40 dB must give L + R = p1 + p2 (the mono sum is the
  one drum), and for strikes of one hand alone L = (1 + P/2) mid and
  R = (1 - P/2) mid with mid = (p1 + p2) / 2 (the copy of the drum that hand
  plays alone is the drum itself): left hand left, right hand right;
- at +30 dB the file is the -40 dB render times 10^(70/20) through the
  documented curve (linear to -6 dBFS, then knee + (c - knee) tanh(...) into
  c = 0.944061 = -0.5 dBFS), and never above c; the printed peaks match the file
  and the unlimited signal;
- render-bits 16 and 24 write integer PCM of that width, equal to the float
  render within one step of the format;
- bad render-mix / render-bits values print one error line each, and the render
  still writes."""
import argparse
import os
import re
import subprocess

import numpy as np

from ictus_tools import e2e_util as u
from ictus_tools.checks import check
from ictus_tools.pdrun import PD_BATCH, PD_ENV, error_lines, make_workdir, read_wav_any

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
build = os.path.abspath(args.build)
work = make_workdir("ictus-render-out-")
SR = 48000

# Strikes of both hands at forte speeds, some 2 ms apart (the sticks meet the
# head's ringing from the other one), and a passage of the left hand alone.
strikes = [(0.050, 1, 6.0, 0.33, 180.0), (0.052, 0, 5.5, 0.34, 2.0), (0.300, 1, 8.0, 0.30, 175.0),
           (0.420, 0, 3.0, 0.40, -10.0), (0.600, 1, 2.0, 0.35, 170.0), (0.700, 0, 9.0, 0.33, 0.0)]
left_alone = [(0.050, 0, 6.0, 0.33, 0.0), (0.400, 0, 2.5, 0.5, 30.0), (0.600, 0, 8.0, 0.2, -5.0)]


def events_file(name, hits):
    lines, prev_us = ["0 render-drum t60 0.3;"], 0
    for t, hand, v, r, th in hits:
        us = int(round(t * 1e6))
        d = us - prev_us
        prev_us = us
        lines.append("%d.%03d hit %d 0 0 %g %g %g 50 0.2 8 0.5 %.6f;"
                     % (d // 1000, d % 1000, hand, v, r, th, t))
    path = os.path.join(work, name)
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
    return path


def render(events, tag, *sends, seconds=1.2):
    wav = os.path.join(work, tag + ".wav")
    cmd = PD_BATCH + ["-r", str(SR), "-path", os.path.join(build, "ictus"), "-open", u.RENDER_PATCH]
    for s in sends:
        cmd += ["-send", s]
    cmd += ["-send", "render-file " + events, "-send", "render-out " + wav,
            "-send", "render-seconds %g" % seconds]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=120, env=PD_ENV)
    log = proc.stdout + proc.stderr
    check(proc.returncode == 0, "pd rendered %s: %s" % (tag, log[-2000:]))
    x, sr, bits, is_float = read_wav_any(wav)
    check(sr == SR and x.shape[1] == 2 and np.all(np.isfinite(x)), "%s: 2 finite channels at %d Hz"
          % (tag, SR))
    return x, bits, is_float, log


def report(log):
    m = re.search(r"^ictus-render: peak_in_dbfs (\S+) peak_out_dbfs (\S+) gain_db (\S+)$", log, re.M)
    check(m is not None, "the render printed its peak report")
    return float(m.group(1)), float(m.group(2)), float(m.group(3))


both = events_file("both.txt", strikes)
alone = events_file("alone.txt", left_alone)

# --- the mix, in the linear range ------------------------------------------------
pick, _, _, log = render(both, "pickups", "render-mix pickups", "render-gain -40")
check(not error_lines(log), "pickups render: no error lines %s" % error_lines(log))
st, _, _, log = render(both, "stereo", "render-gain -40")
check(not error_lines(log), "stereo render: no error lines %s" % error_lines(log))
scale = float(np.abs(pick).max())
check(scale > 1e-4, "the drum sounds at -40 dB (peak %g)" % scale)
err = float(np.abs((st[:, 0] + st[:, 1]) - (pick[:, 0] + pick[:, 1])).max())
print("stereo L+R vs pickups p1+p2: max |difference| %.3g (peak %.3g)" % (err, scale))
check(err <= 1e-5 * scale, "the stereo mix's mono sum is the one drum's p1 + p2")
check(float(np.abs(st[:, 0] - st[:, 1]).max()) > 0.05 * scale, "the stereo mix is not mono")

for pan in (0.5, 1.0, 0.0):
    pk, _, _, _ = render(alone, "alone-pickups", "render-mix pickups", "render-gain -40")
    lr, _, _, _ = render(alone, "alone-stereo-%g" % pan, "render-gain -40", "render-pan %g" % pan)
    mid = (pk[:, 0] + pk[:, 1]) / 2
    e_l = float(np.abs(lr[:, 0] - (1 + pan / 2) * mid).max())
    e_r = float(np.abs(lr[:, 1] - (1 - pan / 2) * mid).max())
    print("left hand alone, pan %g: L - (1+P/2) mid %.3g, R - (1-P/2) mid %.3g" % (pan, e_l, e_r))
    check(max(e_l, e_r) <= 1e-5 * float(np.abs(mid).max()),
          "left hand alone at pan %g: L = %.2f mid, R = %.2f mid" % (pan, 1 + pan / 2, 1 - pan / 2))

# --- gain and the soft limiter -----------------------------------------------------
# the patch's constants, documented: knee 0.501187 (-6 dBFS), ceiling 0.944061 (-0.5 dBFS)
knee, ceiling = 0.501187, 0.944061


def limiter(v):
    a = np.abs(v)
    return np.where(a <= knee, v, np.sign(v) * (knee + (ceiling - knee) * np.tanh((a - knee) / (ceiling - knee))))


hot, _, _, log = render(both, "hot", "render-gain 30")
check(not error_lines(log), "hot render: no error lines")
unlimited = st * 10 ** (70 / 20)
want = limiter(unlimited)
err = float(np.abs(hot - want).max())
peak_db = 20 * np.log10(float(np.abs(hot).max()))
print("+30 dB: unlimited peak %.2f dBFS, file peak %.3f dBFS, |file - curve| max %.3g"
      % (20 * np.log10(float(np.abs(unlimited).max())), peak_db, err))
check(float(np.abs(unlimited).max()) > 4, "the +30 dB render drives the limiter hard")
check(err <= 2e-4, "+30 dB: the file is the -40 dB render x 10^(70/20) through the limiter's curve")
# (+1e-6: the float32 sum knee + (ceiling - knee) in the patch, a few ulps)
check(float(np.abs(hot).max()) <= ceiling + 1e-6 and peak_db <= -0.3,
      "+30 dB: no sample above the ceiling, 0.944061 = -0.5 dBFS (%.4f dBFS)" % peak_db)
p_in, p_out, g = report(log)
check(g == 30 and abs(p_out - peak_db) < 0.01 and
      abs(p_in - 20 * np.log10(float(np.abs(unlimited).max()))) < 0.01,
      "the report gives the gain, the unlimited peak and the file's (%g %g %g)" % (p_in, p_out, g))

# --- sample formats ------------------------------------------------------------------
flt, bits, is_float, _ = render(both, "f32", "render-gain -10")
check(bits == 32 and is_float, "default: 32-bit float")
for b in (16, 24):
    x, bits, is_float, log = render(both, "pcm%d" % b, "render-gain -10", "render-bits %d" % b)
    lsb = 2.0 ** (1 - b)
    err = float(np.abs(x - flt).max())
    print("%d-bit: |pcm - float| max %.3g (1 step %.3g)" % (b, err, lsb))
    check(bits == b and not is_float and not error_lines(log), "render-bits %d: %d-bit PCM" % (b, b))
    check(err <= lsb, "render-bits %d: within one step of the float render" % b)

# --- bad options ---------------------------------------------------------------------
x, bits, _, log = render(both, "bad", "render-mix wide", "render-bits 12", "render-gain -10")
errs = error_lines(log)
check(len(errs) == 2 and "render-mix" in errs[0] + errs[1] and "render-bits" in errs[0] + errs[1]
      and "wide" in " ".join(errs) and "12" in " ".join(errs),
      "bad render-mix and render-bits: one error line each, naming the value: %s" % errs)
check(bits == 32 and float(np.abs(x - flt).max()) == 0.0, "... and the render is the default one")
print("PASS")
