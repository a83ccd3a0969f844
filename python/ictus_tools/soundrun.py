"""Shared by the tests of the sound models: render an events file (the qlist
format of ictus-render.pd) through patches/sound/ictus-sound-render.pd with a
chosen model in real pd batch mode, and simple analysis (onsets, RMS)."""
import os
import subprocess

import numpy as np

from ictus_tools import ROOT
from ictus_tools.checks import check
from ictus_tools.pdrun import (PD, PD_BATCH, PD_ENV, error_lines, make_workdir,  # noqa: F401
                               read_wav_float)

RENDER = os.path.join(ROOT, "patches", "sound", "ictus-sound-render.pd")
MODELS = ("clips", "synth", "modal")


def write_events(path, strokes, head=()):
    """strokes: (time_ms, hand, velocity, r_over_a, theta_deg), or (time_ms,
    "text") for a control line at that time (e.g. "render-drum model synth");
    head: lines at time 0 (e.g. 'render-drum t60 0.02'). Times are written as
    differences in whole microseconds, as `ictusd render` does, so they add up
    exactly."""
    lines = ["0 %s;" % h for h in head]
    prev_us = 0
    for item in strokes:
        us = int(round(item[0] * 1000))
        if isinstance(item[1], str):
            lines.append("%.3f %s;" % ((us - prev_us) / 1000.0, item[1]))
            prev_us = us
            continue
        t_ms, hand, v, r, theta = item
        lines.append("%.3f hit %d 0 0 %g %g %g %.1f 0.01 1.2 0.1 %.6f;"
                     % ((us - prev_us) / 1000.0, hand, v, r, theta, 50.0 * v, us / 1e6))
        prev_us = us
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def render(build, model, events, wav, seconds, sr=48000, timeout=120):
    cmd = PD_BATCH + ["-r", str(sr), "-path", os.path.join(build, "ictus"), "-open", RENDER,
                      "-send", "render-model %s" % model, "-send", "render-file %s" % events,
                      "-send", "render-out %s" % wav, "-send", "render-seconds %.6g" % seconds]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, env=PD_ENV)
    log = proc.stdout + proc.stderr
    check(proc.returncode == 0 and not error_lines(log),
          "%s: ictus-sound-render ran cleanly at %d Hz: %s" % (model, sr, error_lines(log)))
    x, file_sr = read_wav_float(wav)
    check(file_sr == sr and x.shape == (int(round(seconds * sr)), 2),
          "%s: WAV is 2 channels, %d Hz, %g s (%s)" % (model, sr, seconds, x.shape))
    return x


def onsets(x, times_ms, sr, threshold=1e-6, quiet=200):
    """First sample with |x| > threshold after each expected time's predecessor
    went quiet: searched from `quiet` samples before the expected sample, which
    must itself be below threshold (checked by the caller through the result)."""
    y = np.abs(x).max(axis=1)
    out = []
    for t in times_ms:
        e = int(np.floor(t * sr / 1000.0 + 0.5))
        lo = e - quiet
        nz = np.flatnonzero(y[lo:] > threshold)
        out.append((lo + nz[0]) if len(nz) else -1)
    return out


def rms(x, start, ms, sr):
    n = int(round(ms * sr / 1000.0))
    return float(np.sqrt(np.mean(x[start:start + n] ** 2)))
