"""How many modes a drum needs, in the real pd binary (docs/sound.md, "Bandwidth").

Each drum preset (tom, floor-tom, timpani, frame) is struck ff by the physics' stick (14 g
at 6 m/s, r/a 0.3, its contact~) once with the preset's own mode count and once with four
times as many, on copies of the same head; 1 s of pickup 1. With the contact patch and the
static compliance of the modes left out (docs/membrane.md, "The contact patch"), more modes
add their own band and leave the band below 1 kHz, where a drum's pitch and body lie, as it
was: the difference there holds less than -40 dB of the signal's energy. Without them
(`patch 0`: a point force on a truncated head, which meets the stick too stiff) the contact
itself changes with the count and the low band moves by far more (checked too, so that the
comparison can fail). The full-band changes are printed."""
import argparse
import os

import numpy as np

from ictus_tools.checks import check, finish, keep_going
from ictus_tools.pdrun import Patch, make_workdir, read_wav_float, recorder, run_pd

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
args.build = os.path.abspath(args.build)

PRESETS = ["tom", "floor-tom", "timpani", "frame", "kick"]
SR = 48000
SECONDS = 1.0
LOW_HZ = 1000.0
work = make_workdir("ictus-bandwidth-")
keep_going()


def render(extra):
    """Pickup 1 of each preset at its own count and at 4x, `extra` sent to every head."""
    wav = os.path.join(work, "bw%s.wav" % extra.replace(" ", ""))
    p = Patch(declare="-path %s/ictus" % args.build)
    drums, tables = [], []
    for k, preset in enumerate(PRESETS):
        for times in (1, 4):
            name = "bw-%d-%d" % (k, times)
            m, c = p.obj("membrane~ %s" % name), p.obj("contact~ %s" % name)
            drums.append((m, c, preset, times))
            tables.append((m, 0, name))
    trig = recorder(p, tables, SECONDS, SR, wav)
    for m, c, preset, times in drums:
        # the preset (1024 modes, membrane_presets.c), then 4096 on the second copy
        msg = p.msg("preset %s%s" % (preset, "".join(" \\, " + e for e in extra.split(";") if e)))
        p.connect(trig, 1, msg, 0)
        p.connect(msg, 0, m, 0)
        if times > 1:
            more = p.msg("modes 4096")
            p.connect(trig, 1, more, 0)
            p.connect(more, 0, m, 0)
        hit = p.msg("mass 0.014 \\, hit 6 0.3 0")
        p.connect(trig, 1, hit, 0)
        p.connect(hit, 0, c, 0)
    rc, log = run_pd(p.text(), args.build, sr=SR, workdir=work)
    check(rc == 0, "pd rendered (%s)" % (extra or "defaults"))
    x, _ = read_wav_float(wav)
    return x


def changes(x, k):
    a, b = x[:, 2 * k].astype(float), x[:, 2 * k + 1].astype(float)
    d, ref = np.abs(np.fft.rfft(a - b)) ** 2, np.abs(np.fft.rfft(b)) ** 2
    f = np.fft.rfftfreq(len(a), 1.0 / SR)
    low = f < LOW_HZ
    return (10 * np.log10(d[low].sum() / ref.sum()), 10 * np.log10(d.sum() / ref.sum()))


with_patch, point = render(""), render("patch 0")
for k, preset in enumerate(PRESETS):
    low, full = changes(with_patch, k)
    low0, full0 = changes(point, k)
    print("%-9s 1024 -> 4096 modes: below 1 kHz %.1f dB, all %.1f dB; point force: %.1f, %.1f dB"
          % (preset, low, full, low0, full0))
    check(low < -40.0, "%s: 4x the modes leave the band below 1 kHz within -40 dB (%.1f)"
          % (preset, low))
    check(low0 > low + 10.0, "%s: with a point force on the truncated head the low band moves "
          "by more (%.1f dB)" % (preset, low0))
finish()
