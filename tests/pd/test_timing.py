"""A strike scheduled by [delay X] lands on sample round(X * sr / 1000) of the
output, to the sample, at 44.1, 48 and 96 kHz and for a membrane~ in the main
patch (64-sample blocks) and in subpatches with [block~ 1] and [block~ 1024].
The onset is found in the rendered WAV (first non-zero sample; the membrane is
silent before the strike). A [block~ 1024] subpatch in a 64-sample parent
delays its signal by 1024 - 64 = 960 samples (Pd's reblocking: it gathers 1024
input samples before it computes); [block~ 1] adds no delay."""
import argparse
import os

import numpy as np

from ictus_tools.checks import check
from ictus_tools.pdrun import make_workdir, Patch, error_lines, read_wav_float, recorder, run_pd

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
args.build = os.path.abspath(args.build)

delays_ms = [123.45, 1000.0 / 3.0, 7.0, 250.0]
work = make_workdir("ictus-timing-")
for sr in (44100, 48000, 96000):
    for block in (None, 1, 1024):
        p = Patch(declare="-path %s/ictus" % args.build)
        sources = []
        for i, _ in enumerate(delays_ms):
            # one membrane per delay, so each onset is the first sound of its output
            if block:
                sub = Patch()
                inl = sub.obj("inlet")
                mem = sub.obj("membrane~")
                out = sub.obj("outlet~")
                sub.obj("block~ %d" % block)
                sub.connect(inl, 0, mem, 0)
                sub.connect(mem, 0, out, 0)
                sources.append(p.subpatch("sub%d" % i, sub))
            else:
                sources.append(p.obj("membrane~"))
        wav = os.path.join(work, "timing-%d-%s.wav" % (sr, block))
        trig = recorder(p, [(s, 0, "t%d" % i) for i, s in enumerate(sources)], 0.4, sr, wav)
        for s, d in zip(sources, delays_ms):
            dl = p.obj("delay %.17g" % d)
            st = p.msg("strike 0.3 0 0.01")
            p.connect(trig, 0, dl, 0)
            p.connect(dl, 0, st, 0)
            p.connect(st, 0, s, 0)
        rc, log = run_pd(p.text(), args.build, sr=sr, workdir=work)
        check(rc == 0 and not error_lines(log), "pd ran cleanly (sr %d, block %s)" % (sr, block))
        x, _ = read_wav_float(wav)
        latency = (block - 64) if block and block > 64 else 0
        for ch, d in enumerate(delays_ms):
            y = x[:, ch]
            check(np.all(np.isfinite(y)), "finite output")
            nz = np.flatnonzero(y != 0)
            expected = int(np.floor(d * sr / 1000.0 + 0.5)) + latency
            check(len(nz) > 0 and nz[0] == expected,
                  "sr %d block %s: strike at %.4f ms -> onset sample %s, expected %d"
                  % (sr, block, d, nz[0] if len(nz) else None, expected))

# A strike sent while DSP is off lands on the first sample once DSP is back on
# (not at a time computed from the stale anchor of the earlier run). tabwrite~
# only advances while DSP runs, so the table index counts DSP samples: DSP runs
# 0 .. 100 ms (4800 samples at 48 kHz), stops, the strike comes at 150 ms, DSP
# resumes at 200 ms: the onset must be at index 4800.
sr = 48000
p = Patch(declare="-path %s/ictus" % args.build)
mem = p.obj("membrane~")
wav = os.path.join(work, "timing-dsp-off.wav")
trig = recorder(p, [(mem, 0, "t")], 0.4, sr, wav)
for d, text in ((100.0, "\\; pd dsp 0"), (150.0, "strike 0.3 0 0.01"), (200.0, "\\; pd dsp 1")):
    dl = p.obj("delay %g" % d)
    m = p.msg(text)
    p.connect(trig, 0, dl, 0)
    p.connect(dl, 0, m, 0)
    p.connect(m, 0, mem, 0)
rc, log = run_pd(p.text(), args.build, sr=sr, workdir=work)
check(rc == 0 and not error_lines(log), "pd ran cleanly (DSP off and on)")
x, _ = read_wav_float(wav)
nz = np.flatnonzero(x[:, 0] != 0)
check(len(nz) > 0 and nz[0] == 4800,
      "strike while DSP is off lands when DSP resumes: onset %s, expected 4800"
      % (nz[0] if len(nz) else None))

# A membrane~ in a [switch~] subpatch switched off from 100 to 200 ms: its
# counter stood still meanwhile, so it must re-anchor when switched on again;
# a strike at 251.3 ms then lands on sample round(251.3 * 48) = 12062 (the
# parent records all along).
sub = Patch()
inl = sub.obj("inlet")
rt = sub.obj("route float")
mem = sub.obj("membrane~")
out = sub.obj("outlet~")
sw = sub.obj("switch~")
sub.connect(inl, 0, rt, 0)
sub.connect(rt, 0, sw, 0)
sub.connect(rt, 1, mem, 0)
sub.connect(mem, 0, out, 0)
p = Patch(declare="-path %s/ictus" % args.build)
s = p.subpatch("switched", sub)
wav = os.path.join(work, "timing-switch.wav")
trig = recorder(p, [(s, 0, "t")], 0.4, sr, wav)
for d, text in ((0.0, "set 1"), (100.0, "set 0"), (200.0, "set 1"), (251.3, "strike 0.3 0 0.01")):
    dl = p.obj("delay %g" % d)
    # floats switch the subpatch, strikes go to membrane~
    m = p.msg(text.replace("set ", "")) if text.startswith("set") else p.msg(text)
    p.connect(trig, 0, dl, 0)
    p.connect(dl, 0, m, 0)
    p.connect(m, 0, s, 0)
rc, log = run_pd(p.text(), args.build, sr=sr, workdir=work)
check(rc == 0 and not error_lines(log), "pd ran cleanly (switch~)")
x, _ = read_wav_float(wav)
nz = np.flatnonzero(x[:, 0] != 0)
check(len(nz) > 0 and nz[0] == 12062,
      "strike after switch~ resumes is sample-accurate: onset %s, expected 12062"
      % (nz[0] if len(nz) else None))
