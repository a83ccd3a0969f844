"""[ictus-sound-panel]'s preset selector reaches membrane~ (docs/ui.md): in the real pd
(batch), the panel drives [ictus-sound modal] as in the main patch; one soft strike is
recorded after the preset is chosen, by a click on the selector (a number to its receive
name, ictus-sound-panel-preset) or by the panel's inlet (preset NAME). The recording
must have a spectral peak within 2 % of the preset head's (0,1) mode computed here,
f01 = j01 / (2 pi a) sqrt(T / sigma), from the head in membrane_presets.c (radius,
tension, areal density; the tom's with the air's mass on both faces,
ictus_tools.drumtone.f01; the largest within +-10 %, parabolic refinement), and of the four
heads' f01 its own must be the loudest. The selector shows the chosen name; an unknown name is named in an
error line and sends nothing."""
import argparse
import os
import subprocess
import tempfile

import numpy as np

from ictus_tools import uitest
from ictus_tools.checks import check
from ictus_tools.drumtone import f01
from ictus_tools.pdrun import read_wav_float

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
build = os.path.abspath(args.build)

SR = 48000
NAMES = ["paper", "snare", "tom", "floor-tom", "timpani", "frame", "kick"]  # the selector's order
# radius m, tension N/m, areal density kg/m^2, the air's faces (externals/core/membrane_presets.c)
HEADS = {"paper": (0.178, 3000.0, 0.262), "tom": (0.1524, 1465.7, 0.491, 2.0),
         "floor-tom": (0.2032, 878.0, 0.345), "frame": (0.2286, 599.0, 0.262),
         "kick": (0.2794, 556.1, 0.345)}


def render(choose, work, tag):
    """One soft strike (1 m/s at r/a 0.3) on [ictus-sound modal] after `choose` (a FUDI
    message box's text) -> (mono samples, pd's output lines)."""
    wav = os.path.join(work, "%s.wav" % tag)
    patch = os.path.join(work, "%s.pd" % tag)
    with open(patch, "w") as f:
        f.write("#N canvas 0 0 600 400 12;\n"
                "#X obj 10 10 loadbang;\n"                              # 0
                "#X obj 10 40 t b b b;\n"                               # 1
                "#X msg 200 70 %s;\n"                                   # 2
                "#X obj 10 100 ictus-sound-panel;\n"                    # 3
                "#X obj 10 470 ictus-sound modal;\n"                    # 4
                "#X obj 10 500 tabwrite~ rec;\n"                        # 5
                "#X obj 300 500 array define rec %d;\n"                 # 6
                "#X obj 100 70 delay 10;\n"                             # 7
                "#X msg 100 430 1 1 0.3 0;\n"                           # 8
                "#X obj 300 10 delay 1300;\n"                           # 9
                "#X obj 300 40 t b b;\n"                                # 10
                "#X msg 300 70 write -wave -bytes 4 %s rec;\n"          # 11
                "#X obj 300 100 soundfiler;\n"                          # 12
                "#X msg 400 130 \\; pd quit;\n"                         # 13
                "#X obj 200 470 print snd;\n"                           # 14
                "#X connect 0 0 1 0;\n#X connect 1 2 2 0;\n#X connect 2 0 3 0;\n"
                "#X connect 3 0 4 0;\n#X connect 3 0 14 0;\n#X connect 4 0 5 0;\n"
                "#X connect 1 1 5 0;\n#X connect 1 0 7 0;\n#X connect 7 0 8 0;\n"
                "#X connect 8 0 4 0;\n#X connect 0 0 9 0;\n#X connect 9 0 10 0;\n"
                "#X connect 10 1 11 0;\n#X connect 11 0 12 0;\n#X connect 10 0 13 0;\n"
                % (choose, SR * 13 // 10, wav))
    proc = subprocess.run(uitest.PD_BATCH + ["-r", str(SR), "-path", os.path.join(build, "ictus"),
                                             "-open", patch, "-send", "pd dsp 1"],
                          capture_output=True, text=True, timeout=120, env=uitest.PD_ENV)
    lines = [l.strip() for l in (proc.stdout + proc.stderr).splitlines() if l.strip()]
    check(proc.returncode == 0, "%s: pd ran (exit %d)" % (tag, proc.returncode))
    x, rate = read_wav_float(wav)
    check(rate == SR and np.all(np.isfinite(x)), "%s: recorded at %d Hz, finite" % (tag, rate))
    return x.mean(axis=1), lines


def spectrum(x):
    """|FFT| of 20 ms .. 1.2 s after the strike (Hann window, zero-padded to 2^20 points)."""
    seg = x[int(0.02 * SR):int(1.2 * SR)]
    return np.abs(np.fft.rfft(seg * np.hanning(len(seg)), 1 << 20))


def peak_near(mag, f):
    """The spectrum's largest peak within +-10 % of f (Hz, parabolic refinement), or None
    when the largest value there is at the window's edge (no peak inside)."""
    n = 2 * (len(mag) - 1)
    lo, hi = int(0.9 * f * n / SR), int(1.1 * f * n / SR)
    k = lo + int(np.argmax(mag[lo:hi]))
    if k in (lo, hi - 1):
        return None
    a, b, c = np.log(mag[k - 1:k + 2])
    return (k + 0.5 * (a - c) / (a - 2 * b + c)) * SR / n


def loudest_head(mag):
    """Of the heads' f01, the one where the spectrum is largest."""
    n = 2 * (len(mag) - 1)
    return max(HEADS, key=lambda k: mag[int(round(f01(*HEADS[k]) * n / SR))])


with tempfile.TemporaryDirectory(prefix="ictus-ui-preset-") as work:
    for name, head in HEADS.items():
        want = f01(*head)
        for how, choose in (("selector", "\\; ictus-sound-panel-preset %d" % NAMES.index(name)),
                            ("inlet", "preset %s" % name)):
            x, lines = render(choose, work, "%s-%s" % (name, how))
            sent = [l for l in lines if l.startswith("snd: preset")]
            check(sent == ["snd: preset %s" % name],
                  "%s (%s): the panel sends 'preset %s' (%s)" % (name, how, name, sent))
            mag = spectrum(x)
            got = peak_near(mag, want)
            check(got is not None and abs(got - want) <= 0.02 * want,
                  "%s (%s): a mode at %s Hz, the head's f01 %.1f Hz (within 2 %%)"
                  % (name, how, got and round(got, 1), want))
            check(loudest_head(mag) == name, "%s (%s): of the heads' f01 %s Hz, the loudest "
                  "is its own" % (name, how, {k: round(f01(*v), 1) for k, v in HEADS.items()}))
            bad = uitest.error_lines("\n".join(lines))
            check(not bad, "%s (%s): no error lines (%s)" % (name, how, bad))
    # an unknown name: named, nothing sent, the sound keeps its head (paper's f01)
    x, lines = render("preset bongo", work, "unknown")
    check(any("ictus-sound-panel: preset: expected one of paper snare tom floor-tom timpani "
              "frame kick - got: bongo" in l for l in lines), "an unknown preset is named: %s"
          % [l for l in lines if "preset" in l])
    check(not any(l.startswith("snd: preset") for l in lines), "an unknown preset sends nothing")
    check(loudest_head(spectrum(x)) == "paper",
          "after an unknown preset the head is membrane~'s default, the paper's")
print("PASS")
