"""Offline: patches/ictus-render.pd plays an events file in the format of
`ictusd render` (daemon/include/ictus/sim/strike_event.hpp, docs/osc.md:
`<delay_ms since previous line> hit <hand> <drum> <bounce> <normal_velocity_mps>
<r_over_a> <theta_deg> <peak_force_n> <impulse_n_s> <duration_ms>
<tangential_velocity_mps> <time_s> <stick_mass_kg>;`) in real pd batch mode, and each
stroke starts on the sample its time names: at 48 kHz with the stick mass, at 44.1 kHz
in the older 11-number format (no mass: the sticks keep contact~'s own).

Strike times are drawn here (>= 200 ms apart, both hands, fractional ms), away
from half-sample ties; the file holds their differences. The drum rings briefly
(t60 10 ms, set through render-drum), so each onset follows silence: the onset
is the first sample with |y| > 1e-6 after the previous stroke died away, and it
must be exactly round(t * sr / 1000) (one sample is 0.02 ms, far inside 1 ms).
A faster stick must hit harder (peak within 5 ms), so the velocity field is read; a
heavier one stays longer on the head (render-reports: contact~'s durations), so the
mass is read: a stick of 0.04 kg against one of 0.01 kg on a spring-like head, twice
as long (sqrt of the mass ratio), accepted within 1.6..2.4. A line with fewer than
11 numbers is refused with an error naming ictus-render."""
import argparse
import os
import subprocess

import numpy as np

from ictus_tools import ROOT
from ictus_tools.checks import check
from ictus_tools.pdrun import PD_BATCH, PD_ENV, error_lines, make_workdir, read_wav_float

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
build = os.path.abspath(args.build)
render = os.path.join(ROOT, "patches", "ictus-render.pd")
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
    with_mass = sr == 48000
    # the stick mass: 0.01 or 0.04 kg in turn every 6 strokes (both hands, both speeds)
    masses = [0.01 if (i // 6) % 2 == 0 else 0.04 for i in range(len(times))]
    lines, prev = ["0 render-drum t60 0.01;"], 0.0
    for i, (tm, v) in enumerate(zip(times, velocities)):
        # same point for every stroke, so that peaks compare by velocity alone
        lines.append("%.3f hit %d 0 %d %g 0.3 45 %.1f 0.01 1.2 0.1 %.6f%s;"
                     % (tm - prev, i % 2, i % 4 == 3, v, 50.0 * v, tm / 1000.0,
                        " %.5f" % masses[i] if with_mass else ""))
        prev = tm
    events = os.path.join(work, "events-%d.txt" % sr)
    with open(events, "w") as f:
        f.write("\n".join(lines) + "\n")
    wav = os.path.join(work, "out-%d.wav" % sr)
    seconds = round(times[-1] / 1000.0 + 0.3, 3)
    cmd = PD_BATCH + ["-r", str(sr), "-path", os.path.join(build, "ictus"), "-open", render,
                      "-send", "render-file %s" % events, "-send", "render-out %s" % wav, "-send",
                      "render-seconds %.3f" % seconds]
    reports = os.path.join(work, "reports-%d.txt" % sr)
    if with_mass:
        cmd += ["-send", "render-reports %s" % reports]
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
    for m in sorted(set(masses)) if with_mass else [None]:
        group = [i for i in range(len(times)) if m is None or masses[i] == m]
        loud = [peaks[i] for i in group if velocities[i] == 4.0]
        soft = [peaks[i] for i in group if velocities[i] == 1.0]
        check(min(loud) > 1.5 * max(soft),
              "4 m/s strokes peak higher than 1 m/s strokes%s: min %.3g vs max %.3g"
              % (" (stick %g kg)" % m if m else "", min(loud), max(soft)))
    if with_mass:
        with open(reports) as f:
            rows = [[float(w) for w in r.split()] for r in f.read().split(";") if r.strip()]
        check(len(rows) == len(times)
              and [int(r[1]) for r in rows] == [i % 2 for i in range(len(times))],
              "one contact report per stroke, of its hand (%d for %d)" % (len(rows), len(times)))
        light = np.mean([r[2] for r, m in zip(rows, masses) if m == 0.01])
        heavy = np.mean([r[2] for r, m in zip(rows, masses) if m == 0.04])
        print("contact durations: 0.01 kg %.3f ms, 0.04 kg %.3f ms (ratio %.3f)"
              % (light, heavy, heavy / light))
        check(1.6 <= heavy / light <= 2.4, "the stick mass reaches contact~: 4x the mass, "
              "%.2fx the contact duration (a spring's: 2)" % (heavy / light))

# A hit line with fewer than 11 numbers is refused, naming ictus-render; the others play.
events = os.path.join(work, "short.txt")
with open(events, "w") as f:
    f.write("10 hit 0 0 0 2 0.3 45;\n10 hit 1 0 0 2 0.3 45 100 0.01 1.2 0.1 0.02;\n")
wav = os.path.join(work, "short.wav")
reports = os.path.join(work, "short-reports.txt")
cmd = PD_BATCH + ["-path", os.path.join(build, "ictus"), "-open", render, "-send",
                  "render-file %s" % events, "-send", "render-out %s" % wav, "-send",
                  "render-seconds 0.2", "-send", "render-reports %s" % reports]
proc = subprocess.run(cmd, capture_output=True, text=True, timeout=60, env=PD_ENV)
log = proc.stdout + proc.stderr
with open(reports) as f:
    rows = [r.split() for r in f.read().split(";") if r.strip()]
check(proc.returncode == 0 and "error: ictus-render: a hit line needs 11 numbers" in log
      and "0 0 0 2 0.3 45" in log and len(rows) == 1 and rows[0][1] == "1",
      "a 6-number hit line is refused with an error naming ictus-render, the 11-number one "
      "plays: %s %s" % (log, rows))

# A missing events file is reported, naming it; the patch still writes and quits.
wav = os.path.join(work, "missing.wav")
cmd = PD_BATCH + ["-path", os.path.join(build, "ictus"), "-open", render, "-send",
                  "render-file %s/nope.txt" % work, "-send", "render-out %s" % wav, "-send",
                  "render-seconds 0.1"]
proc = subprocess.run(cmd, capture_output=True, text=True, timeout=60, env=PD_ENV)
log = proc.stdout + proc.stderr
check(proc.returncode == 0 and "nope.txt" in log and os.path.isfile(wav),
      "a missing events file is named in an error and pd still quits")
