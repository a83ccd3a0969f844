"""Two [ictus-kit] in one patch (docs/pd-osc.md, "[ictus-kit]"): each kit's names are its own
($0-kit without an argument), so a drum configured on one kit and struck on it plays on that
kit only. They used to share render-kit-hit, render-kit-N and the catch~ of their signal
outlets: each strike played on both kits, and pd said the catch~ were duplicates. In batch pd,
seeded: drum 2 configured on kit A's right inlet only and struck on A's left inlet only; A's
signal outlets must carry every strike, B's stay exactly 0, pd's log without an error line;
then the same with the roles swapped. And [ictus-kit NAME] uses NAME as its names' prefix: a
drum configured by NAME-3 messages from another part of the patch and struck by NAME-hit
lines plays on that kit only, and what the kit sends its drums (its strikes on NAME-hit) can be
heard by [r NAME-hit].

    PYTHONPATH=python python3 tests/pdosc/test_kit_two.py --build build
"""
import argparse
import os
import random

import numpy as np

from ictus_tools.checks import check, failed, keep_going
from ictus_tools.pdrun import Patch, error_lines, make_workdir, read_wav_float, recorder, run_pd

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
args.build = os.path.abspath(args.build)

SR = 48000
SEED = 20261202
DRUM = 2
CONFIG = "drum %d tom1 tom 0.127 1465.7 0 48" % DRUM  # <index> <name> <preset> <radius> ...


def strikes(rng, drum, count=6):
    """(ms, ictus-receive's 19 numbers) of seeded strikes on drum: a hand, 2..5 m/s, r/a,
    theta, the rest as tests/pdosc/test_kit_short.py's, 60..120 ms apart."""
    out, ms = [], 40.0
    for seq in range(1, count + 1):
        ms += rng.uniform(60.0, 120.0)
        fields = [rng.randint(0, 1), round(rng.uniform(2.0, 5.0), 3),
                  round(rng.uniform(0.0, 0.8), 3), round(rng.uniform(0.0, 359.0), 1),
                  0.05, 100, 0, drum, seq, round(ms / 1000.0, 4), 0, 0, 0, 0.01, 1, 0, 0, 1, 0]
        out.append((round(ms, 1), " ".join("%g" % f for f in fields)))
    return out


def hit_lines(rng, drum, count=5):
    """(ms, a hit line as NAME-hit takes it: <hand> <drum> <bounce> <velocity> <r/a> <theta>
    <peak_force> <impulse> <duration_ms> <vt> <time_s>), seeded."""
    out, ms = [], 40.0
    for _ in range(count):
        ms += rng.uniform(60.0, 120.0)
        fields = [rng.randint(0, 1), drum, 0, round(rng.uniform(2.0, 5.0), 3),
                  round(rng.uniform(0.0, 0.8), 3), round(rng.uniform(0.0, 359.0), 1), 10, 0.01,
                  1, 0, round(ms / 1000.0, 4)]
        out.append((round(ms, 1), " ".join("%g" % f for f in fields)))
    return out


def at(p, trig, ms, text, dest, inlet):
    """A message box sent `ms` after recording starts into dest's inlet (dest None: a
    message box of its own, e.g. one starting with a semicolon)."""
    dl, mm = p.obj("delay %g" % ms), p.msg(text)
    p.connect(trig, 0, dl, 0)
    p.connect(dl, 0, mm, 0)
    if dest is not None:
        p.connect(mm, 0, dest, inlet)


def run(p, tag):
    work = make_workdir("ictus-kit-two-")
    rc, log = run_pd(p.text().replace("WAV", os.path.join(work, "out.wav")), args.build,
                     sr=SR, workdir=work)
    check(rc == 0, "%s: pd ran (exit %d)" % (tag, rc))
    check(not error_lines(log), "%s: pd's log has no error line: %s" % (tag, error_lines(log)))
    wav = os.path.join(work, "out.wav")
    return (read_wav_float(wav)[0].astype(np.float64) if os.path.exists(wav) else None), log


def check_plays(x, chans, events, tag):
    """Every strike sounds on chans: the 10 ms after its onset peak above 1e-3 and above the
    2 ms before it (the ringing of the strikes before)."""
    for ms, _ in events:
        i = int(round(ms * SR / 1000.0))
        peak = float(np.max(np.abs(x[i:i + SR // 100, chans])))
        before = float(np.max(np.abs(x[i - SR // 500:i, chans])))
        check(peak > 1e-3 and peak > before, "%s: the strike at %g ms sounds on its kit (peak "
              "%.3g, %.3g in the 2 ms before)" % (tag, ms, peak, before))


def check_silent(x, chans, tag):
    peak = float(np.max(np.abs(x[:, chans])))
    check(peak == 0.0, "%s: the other kit's outlets stay exactly 0 (peak %.3g)" % (tag, peak))


def two_kits(played, rng):
    """Kits 0 and 1, both [ictus-kit]; `played` configured and struck, the other left alone."""
    events = strikes(rng, DRUM)
    seconds = (events[-1][0] + 200.0) / 1000.0
    p = Patch(declare="-path %s/ictus" % args.build)
    kits = [p.obj("ictus-kit"), p.obj("ictus-kit")]
    trig = recorder(p, [(kits[0], 1, "a-l"), (kits[0], 2, "a-r"), (kits[1], 1, "b-l"),
                        (kits[1], 2, "b-r")], seconds, SR, "WAV")
    at(p, trig, 5, CONFIG, kits[played], 1)
    for ms, text in events:
        at(p, trig, ms, text, kits[played], 0)
    tag = "kit %s struck" % "AB"[played]
    x, _ = run(p, tag)
    check(x is not None, "%s: pd wrote the recording" % tag)
    if x is None:
        return
    mine, other = ([0, 1], [2, 3]) if played == 0 else ([2, 3], [0, 1])
    check_plays(x, mine, events, tag)
    check_silent(x, other, tag)


def named_kit(rng):
    """[ictus-kit kitn] beside an [ictus-kit]: drum 3 of kitn configured by kitn-3 messages
    and struck by kitn-hit lines, then one strike through kitn's left inlet, heard on
    [r kitn-hit]."""
    name, drum = "kitn", 3
    events = hit_lines(rng, drum)
    inlet_strike = strikes(rng, drum, count=1)[0][1]
    inlet_ms = events[-1][0] + 150.0
    seconds = (inlet_ms + 200.0) / 1000.0
    p = Patch(declare="-path %s/ictus" % args.build)
    kits = [p.obj("ictus-kit %s" % name), p.obj("ictus-kit")]
    trig = recorder(p, [(kits[0], 1, "n-l"), (kits[0], 2, "n-r"), (kits[1], 1, "u-l"),
                        (kits[1], 2, "u-r")], seconds, SR, "WAV")
    heard = p.obj("r %s-hit" % name)
    pr = p.obj("print heard")
    p.connect(heard, 0, pr, 0)
    config = " ".join("\\; %s-%d %s" % (name, drum, m) for m in
                      ("preset tom", "radius 0.127", "tension 1465.7", "pan 0", "dsp 1"))
    at(p, trig, 5, config, None, 0)
    for ms, text in events:
        at(p, trig, ms, "\\; %s-hit %s" % (name, text), None, 0)
    at(p, trig, inlet_ms, inlet_strike, kits[0], 0)
    tag = "[ictus-kit %s]" % name
    x, log = run(p, tag)
    heard = [l[len("heard: "):].split() for l in log.splitlines() if l.startswith("heard: ")]
    check(len(heard) == len(events) + 1, "%s: [r %s-hit] hears the %d lines sent and the "
          "kit's own strike: %d" % (tag, name, len(events), len(heard)))
    if len(heard) == len(events) + 1:
        check([float(v) for v in heard[-1][:2]] == [float(inlet_strike.split()[0]), drum],
              "%s: the kit's strike on %s-hit is the strike's hand and drum: %s"
              % (tag, name, heard[-1]))
    check(x is not None, "%s: pd wrote the recording" % tag)
    if x is None:
        return
    check_plays(x, [0, 1], events + [(inlet_ms, inlet_strike)], tag)
    check_silent(x, [2, 3], tag)


keep_going()
rng = random.Random(SEED)
two_kits(0, rng)
two_kits(1, rng)
named_kit(rng)
if failed():
    raise SystemExit(1)
print("ok")
