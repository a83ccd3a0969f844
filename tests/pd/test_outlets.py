"""membrane~ computes its second pickup only while something is connected to its
second outlet (docs/externals.md). The first outlet must not notice: rendered
with and without the second outlet connected, it is the same bit for bit; and a
connection made while DSP runs (a `connect` message to the canvas, which makes Pd
rebuild the DSP chain) brings the second pickup back from the next block on, equal
to the render that had it all along, until it is disconnected again. Reference:
the same patch with both outlets connected throughout."""
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
seconds = 0.5
t_connect, t_disconnect = 0.2, 0.3501  # s (the second one inside a block)
work = make_workdir("ictus-outlets-")


def render(name, second):
    """second: 'always' or 'later' (connected at t_connect, disconnected at t_disconnect)."""
    p = Patch(declare="-path %s/ictus" % args.build)
    mem = p.obj("membrane~ drum 0.178 3000 0.26 400")
    con = p.obj("contact~ drum")
    wav = os.path.join(work, name + ".wav")
    # "later": [tabwrite~ right] records a [sig~ 0] until membrane~'s outlet 2 joins it
    right = (mem, 1, "right") if second == "always" else (p.obj("sig~ 0"), 0, "right")
    trig = recorder(p, [(mem, 0, "left"), right], seconds, sr, wav)
    # A linear head: with tension modulation the rebuild's float rounding would move
    # the energy, hence the pitch, and grow into a phase drift over the run.
    lin = p.msg("tensionmod 0")
    p.connect(trig, 0, lin, 0)
    p.connect(lin, 0, mem, 0)
    for delay_ms, text in ((5.0, "hit 2 0.3 0"), (61.3, "hit 0.8 0.6 45"),
                           (150.7, "mass 1 \\, hit 1.5 0.2 100"), (260.1, "hit 3 0.7 300"),
                           (380.9, "hit 1 0.4 30")):
        dl = p.obj("delay %.17g" % delay_ms)
        mm = p.msg(text)
        p.connect(trig, 0, dl, 0)
        p.connect(dl, 0, mm, 0)
        p.connect(mm, 0, con, 0)
    if second == "later":
        tw = right_tw(p)
        for delay_ms, verb in ((t_connect * 1000.0, "connect"),
                               (t_disconnect * 1000.0, "disconnect")):
            dl = p.obj("delay %.17g" % delay_ms)
            mm = p.msg("\\; pd-test.pd %s %d 1 %d 0" % (verb, mem, tw))
            p.connect(trig, 0, dl, 0)
            p.connect(dl, 0, mm, 0)
    rc, log = run_pd(p.text(), args.build, sr=sr, workdir=work)
    check(rc == 0 and not error_lines(log), "pd ran cleanly (%s)" % name)
    x, _ = read_wav_float(wav)
    check(np.all(np.isfinite(x)), "finite output (%s)" % name)
    return x.astype(np.float64)


def right_tw(p):
    """Index of the [tabwrite~ right] box in p."""
    boxes = [l for l in p.lines if l.startswith("#X obj") or l.startswith("#X msg")]
    for i, l in enumerate(boxes):
        if l.endswith(" tabwrite~ right;"):
            return i
    raise SystemExit("no tabwrite~ right")


ref = render("both", "always")
later = render("later", "later")
peak_l, peak_r = np.max(np.abs(ref[:, 0])), np.max(np.abs(ref[:, 1]))
check(peak_l > 1e-4 and peak_r > 1e-4, "the reference is not silent (peaks %.3g, %.3g)"
      % (peak_l, peak_r))
block = 64
# Pd runs the clocks due before a block's end, then computes the block: a connection
# made at logical time t counts from the block that holds t.
on = int(np.floor(t_connect * sr / block)) * block
off = int(np.floor(t_disconnect * sr / block)) * block
check(np.array_equal(ref[:on, 0], later[:on, 0]),
      "pickup 1 is the same bit for bit with pickup 2 skipped (%d samples)" % on)
# A DSP rebuild folds the stick's pending force into the modes at once instead of
# in the next sample's pass: float rounding, as for block sizes (test_blocksize).
d = np.max(np.abs(ref[:, 0] - later[:, 0]))
check(d <= 1e-5 * peak_l, "pickup 1 after the rebuilds: max |diff| %.3g (peak %.3g)" % (d, peak_l))
check(np.all(later[:on, 1] == 0.0), "nothing on outlet 2 before it is connected")
r = later[on:off, 1]
check(np.max(np.abs(r)) > 0.05 * peak_r, "outlet 2 sounds once connected (peak %.3g)"
      % np.max(np.abs(r)))
d = np.max(np.abs(ref[on:off, 1] - r))
check(d <= 1e-5 * peak_r, "outlet 2 once connected equals the reference: max |diff| %.3g" % d)
check(np.all(later[off:, 1] == 0.0), "nothing on outlet 2 after it is disconnected")
