"""Offline: patches/ictus-render.pd plays an events file in the format of
`ictusd render` (daemon/include/ictus/sim/strike_event.hpp, docs/osc.md:
`<delay_ms since previous line> hit <hand> <drum> <bounce> <normal_velocity_mps>
<r_over_a> <theta_deg> <peak_force_n> <impulse_n_s> <duration_ms>
<tangential_velocity_mps> <time_s>;`) in real pd batch mode, and each stroke
starts on the sample its time names.

Strike times are drawn here (>= 200 ms apart, both hands, fractional ms), away
from half-sample ties; the file holds their differences. The drum rings briefly
(t60 10 ms, set through render-drum), so each onset follows silence: the onset
is the first sample with |y| > 1e-6 after the previous stroke died away, and it
must be exactly round(t * sr / 1000) (one sample is 0.02 ms, far inside 1 ms).
A faster stick must hit harder (peak within 5 ms), so the velocity field is read."""
import argparse
import os
import subprocess

import numpy as np

import sys
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "pd"))
from pdrun import PD, PD_ENV, check, error_lines, make_workdir, read_wav_float

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
build = os.path.abspath(args.build)
root = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
render = os.path.join(root, "patches", "ictus-render.pd")
work = make_workdir("ictus-render-")
rng = np.random.default_rng(5)

for sr in (44100, 48000):
    # absolute times (ms), quantized to 1 us as the file writes them
    times = []
    t = 20.0 + rng.uniform(0, 5)
    while len(times) < 16:
        frac = (t * sr / 1000.0) % 1.0
        if abs(frac - 0.5) > 0.05:  # not a tie between two samples
            times.append(round(t, 3))
        t += 200.0 + rng.uniform(0, 60)
    velocities = [1.0 if i % 3 else 4.0 for i in range(len(times))]
    lines, prev = ["0 render-drum t60 0.01;"], 0.0
    for i, (tm, v) in enumerate(zip(times, velocities)):
        # same point for every stroke, so that peaks compare by velocity alone
        lines.append("%.3f hit %d 0 %d %g 0.3 45 %.1f 0.01 1.2 0.1 %.6f;"
                     % (tm - prev, i % 2, i % 4 == 3, v, 50.0 * v, tm / 1000.0))
        prev = tm
    events = os.path.join(work, "events-%d.txt" % sr)
    with open(events, "w") as f:
        f.write("\n".join(lines) + "\n")
    wav = os.path.join(work, "out-%d.wav" % sr)
    seconds = round(times[-1] / 1000.0 + 0.3, 3)
    cmd = [PD, "-nogui", "-nosound", "-batch", "-stderr", "-r", str(sr), "-path",
           os.path.join(build, "ictus"), "-open", render, "-send", "render-file %s" % events,
           "-send", "render-out %s" % wav, "-send", "render-seconds %.3f" % seconds]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=120, env=PD_ENV)
    log = proc.stdout + proc.stderr
    check(proc.returncode == 0 and not error_lines(log),
          "ictus-render ran cleanly at %d Hz: %s" % (sr, error_lines(log)))
    x, file_sr = read_wav_float(wav)
    check(file_sr == sr and x.shape == (int(round(seconds * sr)), 2),
          "WAV is 2 channels, %d Hz, %g s: %s at %d Hz" % (sr, seconds, x.shape, file_sr))
    check(np.all(np.isfinite(x)), "finite output")
    y = np.abs(x).max(axis=1)
    onsets, start = [], 0
    for tm in times:
        expected = int(np.floor(tm * sr / 1000.0 + 0.5))
        # search from halfway between the previous stroke and this one
        lo = (start + expected) // 2
        nz = np.flatnonzero(y[lo:] > 1e-6)
        onsets.append(lo + nz[0] if len(nz) else -1)
        if not (len(nz) > 0 and onsets[-1] - lo > 50):
            check(False, "silence before the stroke at %.3f ms" % tm)
        start = expected
    expected = [int(np.floor(tm * sr / 1000.0 + 0.5)) for tm in times]
    diff = np.array(onsets) - np.array(expected)
    print("sr %d: onset - expected (samples): %s" % (sr, diff.tolist()))
    check(np.all(diff == 0), "every stroke starts on sample round(t * sr / 1000) at %d Hz" % sr)
    peaks = [y[o:o + int(0.005 * sr)].max() for o in onsets]
    loud = [p for p, v in zip(peaks, velocities) if v == 4.0]
    soft = [p for p, v in zip(peaks, velocities) if v == 1.0]
    check(min(loud) > 1.5 * max(soft),
          "4 m/s strokes peak higher than 1 m/s strokes: min %.3g vs max %.3g"
          % (min(loud), max(soft)))

# A missing events file is reported, naming it; the patch still writes and quits.
wav = os.path.join(work, "missing.wav")
cmd = [PD, "-nogui", "-nosound", "-batch", "-stderr", "-path", os.path.join(build, "ictus"),
       "-open", render, "-send", "render-file %s/nope.txt" % work, "-send", "render-out %s" % wav,
       "-send", "render-seconds 0.1"]
proc = subprocess.run(cmd, capture_output=True, text=True, timeout=60, env=PD_ENV)
log = proc.stdout + proc.stderr
check(proc.returncode == 0 and "nope.txt" in log and os.path.isfile(wav),
      "a missing events file is named in an error and pd still quits")
