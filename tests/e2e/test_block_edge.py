"""A strike whose time falls in the last half sample of a DSP block rounds to
the first sample of the next block: it must start there, not a block early.
(tests/e2e/test_main_job.py found a strike of the default score at 9.483993 s
that started 64 samples early at 48 kHz: membrane~'s clock returned offset 0
for an offset equal to the block window.)

An events file in the format of `ictusd render` with strikes at times chosen
against the 64-sample block grid (last half sample of a block, the block's last
sample, its first sample, the middle of a block), played by
patches/ictus-render.pd in the real pd batch mode on a short-decay drum; each
onset (first sample above 1e-7 after silence, e2e_util.detect_onsets) must be
sample round(t * sr), and there must be exactly one onset per strike."""
import argparse
import os

import numpy as np

from ictus_tools import e2e_util as u
from ictus_tools.checks import check
from ictus_tools.pdrun import error_lines, make_workdir

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
build = os.path.abspath(args.build)
work = make_workdir("ictus-e2e-edge-")
BLOCK = 64

for sr in (48000, 44100):
    # sample positions (fractional) relative to a block start 64 k
    offsets = [-0.3, -0.45, -0.7, 0.2, 31.6, -0.3, 0.4, -0.3]
    times_us, positions = [], []
    for i, off in enumerate(offsets):
        k = int(round((0.05 + 0.2 * i) * sr / BLOCK))  # a block ~200 ms apart
        pos = BLOCK * k + off
        t_us = int(np.floor(pos / sr * 1e6 + 0.5))  # the file's microseconds
        times_us.append(t_us)
        positions.append(t_us * sr / 1e6)
    lines, prev = ["0 render-drum t60 0.01;"], 0
    for i, t in enumerate(times_us):
        d = t - prev
        lines.append("%d.%03d hit %d 0 0 3.0 0.3 45 100.0 0.01 1.0 0.1 %.6f;"
                     % (d // 1000, d % 1000, i % 2, t / 1e6))
        prev = t
    events = os.path.join(work, "edge-%d.txt" % sr)
    with open(events, "w") as f:
        f.write("\n".join(lines) + "\n")
    seconds = round(times_us[-1] / 1e6 + 0.2, 3)
    x, file_sr, log = u.render_pd(build, events, os.path.join(work, "edge-%d.wav" % sr),
                                  seconds, sr)
    check(file_sr == sr and not error_lines(log), "rendered at %d Hz cleanly: %s"
          % (sr, error_lines(log)))
    onsets = u.detect_onsets(x, sr)
    expected = [int(np.floor(p + 0.5)) for p in positions]
    print("sr %d: sample positions %s" % (sr, ["%.2f" % p for p in positions]))
    print("sr %d: onset - round(t sr) = %s (block-start expectations: %s)"
          % (sr, [o - e for o, e in zip(onsets, expected)],
             [e % BLOCK == 0 for e in expected]))
    check(len(onsets) == len(expected), "one onset per strike at %d Hz (%d, %d)"
          % (sr, len(onsets), len(expected)))
    check(onsets == expected, "every strike starts on sample round(t * sr) at %d Hz, "
          "block edges included" % sr)
