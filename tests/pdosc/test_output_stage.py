"""[ictus-out~] (docs/pd-osc.md, "The output stage") in pd -batch against its formulas computed
here in numpy on the same input (osc~'s cosine, A cos(2 pi f n / sr)): the soft limiter
y = c + 0.442874 tanh((x - c) / 0.442874), c = x clipped to +-0.501187, on a cosine at 4
(+12 dBFS): every sample as the formula says, none at or above the ceiling 0.944061
(-0.5 dBFS), and a cosine at 0.1 (below the knee) passed unchanged; the width 0 mix (both
channels the mean of the two inputs); gain 6 dB (after its 20 ms ramp) and the inlets added
after the mix.

    PYTHONPATH=python python3 tests/pdosc/test_output_stage.py --build build
"""
import argparse
import os

import numpy as np

from ictus_tools.checks import check
from ictus_tools.pdrun import Patch, make_workdir, read_wav_float, recorder, run_pd, ERROR_RE

SR, F, SECONDS = 48000, 100.0, 0.2
KNEE, SPAN, CEILING = 0.501187, 0.442874, 0.944061


def limiter(x):
    c = np.clip(x, -KNEE, KNEE)
    return c + SPAN * np.tanh((x - c) / SPAN)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    build = os.path.abspath(ap.parse_args().build)
    p = Patch()
    osc = p.obj("osc~ %g" % F)
    amp = {a: p.obj("*~ %g" % a) for a in (4.0, 0.1, 0.3, 0.05)}
    for o in amp.values():
        p.connect(osc, 0, o, 0)
    full, mono, gained = p.obj("ictus-out~ 1"), p.obj("ictus-out~ 0"), p.obj("ictus-out~ 1")
    p.connect(amp[4.0], 0, full, 0)
    p.connect(amp[0.1], 0, full, 1)
    p.connect(amp[0.1], 0, mono, 0)
    p.connect(amp[0.3], 0, mono, 1)
    p.connect(amp[0.1], 0, gained, 0)
    p.connect(amp[0.05], 0, gained, 2)
    lb = p.obj("loadbang")
    gain = p.msg("gain 6")
    p.connect(lb, 0, gain, 0)
    p.connect(gain, 0, gained, 4)
    work = make_workdir("ictus-pdosc-out-")
    wav = os.path.join(work, "out.wav")
    recorder(p, [(full, 0, "fl"), (full, 1, "fr"), (full, 2, "fpre"), (mono, 0, "ml"),
                 (mono, 1, "mr"), (gained, 0, "gl")], SECONDS, SR, wav)
    rc, log = run_pd(p.text(), os.path.join(build, "ictus"), sr=SR, workdir=work)
    check(rc == 0 and not ERROR_RE.search(log), "pd ran cleanly: %s" % log[-300:])
    y, rate = read_wav_float(wav)
    n = np.arange(len(y))
    cos = np.cos(2 * np.pi * F * n / SR)
    err = np.abs(y[:, 0] - limiter(4.0 * cos)).max()
    check(err < 1e-4, "the limiter on a cosine at 4: as the formula to %.2g" % err)
    check(y[:, 0].max() < CEILING and y[:, 0].max() > 0.94 and -y[:, 0].min() < CEILING,
          "never at the ceiling %.6f: peaks %.6f / %.6f" % (CEILING, y[:, 0].max(), y[:, 0].min()))
    check(np.abs(y[:, 2] - 4.0 * cos).max() < 1e-4, "the pre-limiter outlet is the input")
    err = np.abs(y[:, 1] - 0.1 * cos).max()
    check(err < 1e-5, "below the knee the signal passes unchanged (to %.2g)" % err)
    err = max(np.abs(y[:, 3] - 0.2 * cos).max(), np.abs(y[:, 4] - 0.2 * cos).max())
    check(err < 1e-5, "width 0: both channels the mean of the inputs (to %.2g)" % err)
    settled = n >= int(0.03 * SR)
    want = limiter(0.15 * 10 ** (6 / 20) * cos)
    err = np.abs(y[settled, 5] - want[settled]).max()
    check(err < 1e-4, "gain 6 dB on the mix plus the added inlet (to %.2g)" % err)
    print("ok")


if __name__ == "__main__":
    main()
