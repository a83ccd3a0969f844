"""Bad input to membrane~ and contact~: every bad message gets an error line
naming the object and the parameter, the value is clamped or refused, pd does
not crash, and the output stays finite. Symbols such as 'nan' and 'inf' are how
a NaN reaches a Pd message; huge and negative numbers, missing and wrong-typed
arguments, modes 0 and 1000000, a contact~ without a name and one naming a
membrane~ that does not exist are all tried.

Extra arguments are reported and the rest of the message is used: a drum and
its contact~ given position, strike, pickup, tip and set with extra (or, for tip
and set, wrong-typed) arguments sound sample for sample as a twin given the same
messages without them. A hit on a head that moves at the stick faster than it
(just after a strike at the same point) never touches it: its force outlet stays
0 and it reports nothing; the contact~'s next hit reports the duration and peak
of its force outlet."""
import argparse
import os

import numpy as np

from ictus_tools.checks import check
from ictus_tools.pdrun import make_workdir, Patch, read_wav_float, recorder, run_pd

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
args.build = os.path.abspath(args.build)

# (message to membrane~, a substring its error line must contain)
membrane_cases = [
    ("radius nan", "membrane~: radius: value must be a number, got 'nan'"),
    ("radius -1", "membrane~: radius must be in [0.01, 2] m, got -1; using 0.01"),
    ("radius 1e+30", "membrane~: radius must be in [0.01, 2] m, got 1e+30; using 2"),
    ("radius 0.2", None),
    ("tension foo", "membrane~: tension: value must be a number, got 'foo'"),
    ("tension -5", "membrane~: tension must be in [1, 100000] N/m, got -5; using 1"),
    ("tension 3000", None),
    ("density inf", "membrane~: density: value must be a number, got 'inf'"),
    ("density 0", "membrane~: density must be in [0.01, 20] kg/m^2, got 0; using 0.01"),
    ("density 0.26", None),
    ("mass -2", "membrane~: mass must be in [0.00125664, 2.51327] kg, got -2; using 0.00125664"),
    ("modes 0", "membrane~: modes must be in [1, 4096], got 0; using 1"),
    ("modes 1000000", "membrane~: modes must be in [1, 4096], got 1e+06; using 4096"),
    ("modes 0.5", "membrane~: modes must be in [1, 4096], got 0.5; using 1"),
    ("modes 64", None),
    ("t60", "membrane~: t60: missing value"),
    ("t60 -1", "membrane~: t60 must be in [0.005, 60] s, got -1; using 0.005"),
    ("t60 1", None),
    ("hfdamp -3", "membrane~: hfdamp must be in [0, 1000], got -3; using 0"),
    ("gain 1e+07", "membrane~: gain must be in [-1e+06, 1e+06], got 1e+07; using 1e+06"),
    ("gain 1", None),
    ("openness 2", "membrane~: openness must be in [0, 1], got 2; using 1"),
    ("openness nan", "membrane~: openness: value must be a number, got 'nan'"),
    ("openness 0.5", None),
    ("edgedamp -1", "membrane~: edgedamp must be in [0, 10000] N s/m^2, got -1; using 0"),
    ("edgedamp 0", None),
    ("pickup 3 0.5 0", "membrane~: pickup: index must be 1 or 2, got 3"),
    ("pickup 1 2 0", "membrane~: pickup: r/a must be in [0, 1], got 2; using 1"),
    ("pickup 1", "membrane~: pickup: missing r/a"),
    ("pickup 2 0.5 0 9", "membrane~: pickup takes three numbers (index, r/a, theta); extra "
                         "arguments ignored"),
    ("position -0.5 0", "membrane~: position: r/a must be in [0, 1], got -0.5; using 0"),
    ("position 0.3 nan", "membrane~: position: theta (deg) must be a number, got 'nan'"),
    ("position 0.5 0 0.001 9 9", "membrane~: position takes two numbers (r/a, theta); extra "
                                 "arguments ignored"),
    ("strike 0.5", "membrane~: strike: missing theta (deg)"),
    ("strike 0.5 0 nan", "membrane~: strike: impulse (N s) must be a number, got 'nan'"),
    ("strike 0.5 0 1e+09", "membrane~: strike: impulse must be in [0, 10] N s, got 1e+09; using 10"),
    ("strike 0.5 0 -1", "membrane~: strike: impulse must be in [0, 10] N s, got -1; using 0"),
    ("strike 0.5 0 0.001 9 9", "membrane~: strike takes three numbers (r/a, theta, impulse); "
                               "extra arguments ignored"),
    ("strike 0.4 0 0.01", None),
    ("preset tom extra", "membrane~ bad-drum: preset takes one name; extra arguments ignored"),
    ("preset paper", None),
]
contact_cases = [
    ("mass 0", "contact~: mass must be in [0.0001, 10] kg, got 0; using 0.0001"),
    ("mass nan", "contact~: mass: value must be a number, got 'nan'"),
    ("mass 0.05", None),
    ("stiffness -1", "contact~: stiffness must be in [1, 1e+12] N/m^alpha, got -1; using 1"),
    ("stiffness 1e+07", None),
    ("alpha 10", "contact~: alpha must be in [1, 4], got 10; using 4"),
    ("alpha 1.5", None),
    ("damping -1", "contact~: damping must be in [0, 1e+13] N s/m^(alpha+1), got -1; using 0"),
    ("damping 5e+06", None),
    ("hit -1 0.5 0", "contact~: hit: velocity must be in (0, 50] m/s, got -1"),
    ("hit 1e+09 0.5 0", "contact~: hit: velocity must be in (0, 50] m/s, got 1e+09; using 50"),
    ("hit 1 0.5", "contact~: hit: missing theta (deg)"),
    ("hit foo 0.5 0", "contact~: hit: velocity (m/s) must be a number, got 'foo'"),
    ("set", "contact~: set: needs the name of a membrane~"),
    ("tip steel", "contact~: tip: no stick tip named 'steel' (wood, nylon, felt); the tip is "
                  "unchanged"),
    ("tip felt", None),
    ("tip 1", "contact~: tip: expected the name of a stick tip (wood, nylon, felt), got '1'; the "
              "tip is unchanged"),
    ("tip", "contact~: tip: missing the name of a stick tip (wood, nylon, felt); the tip is "
            "unchanged"),
    ("tip felt wood", "contact~: tip takes one name; extra arguments ignored"),
    ("set 1", "contact~: set: needs the name of a membrane~, got '1'; ignored"),
    ("set bad-drum extra", "contact~: set takes one name; extra arguments ignored"),
    ("hit 2 0.3 0", None),
    ("hit 2 0.3 0 5e-05", "contact~: hit: stick mass must be in [0.0001, 10] kg, got 5e-05; "
                          "using 0.0001"),
    ("hit 2 0.3 0 0.0001", None),  # the bound itself, as a float reads it
    ("hit 2 0.3 0 10", None),
    ("hit 2 0.3 0 0.05 7", "contact~: hit takes at most four numbers (velocity, r/a, theta, stick "
                           "mass); extra arguments ignored"),
]

sr = 48000
work = make_workdir("ictus-bad-")
wav = os.path.join(work, "bad.wav")
p = Patch(declare="-path %s/ictus" % args.build)
mem = p.obj("membrane~ bad-drum 1e+30 -5 nan")
con = p.obj("contact~ bad-drum")
p.obj("contact~")                       # no name
p.obj("contact~ no-such-drum")          # nothing to play
p.obj("contact~ no-such-drum granite")  # no such tip
# Twin drums: 'extra-drum' and its contact~ get the messages of extra_cases, 'twin-drum'
# and its the same without what is extra or wrong; both feel the same force at their
# "position" (0.01 N from 60 to 70 ms) and the same strike and hit.
extra_cases = [  # (time ms, message to extra-drum, its error, message to twin-drum)
    (20, "position 0.7 45 0.001 9 9", "membrane~: position takes two numbers (r/a, theta); extra "
                                      "arguments ignored", "position 0.7 45"),
    (30, "pickup 1 0.6 90 9", "membrane~: pickup takes three numbers (index, r/a, theta); extra "
                              "arguments ignored", "pickup 1 0.6 90"),
    (100, "strike 0.4 30 0.01 9 9", "membrane~: strike takes three numbers (r/a, theta, impulse); "
                                    "extra arguments ignored", "strike 0.4 30 0.01")]
extra_contact_cases = [  # (time ms, message to extra-drum's contact~, its error, to twin-drum's)
    (20, "set extra-drum twin-drum", "contact~: set takes one name; extra arguments ignored",
     None),
    (30, "set 1 twin-drum", "contact~: set: needs the name of a membrane~, got '1'; ignored",
     None),
    (40, "tip wood felt", "contact~: tip takes one name; extra arguments ignored", None),
    (50, "tip 1 felt", "contact~: tip: expected the name of a stick tip (wood, nylon, felt), got "
                       "'1'; the tip is unchanged", None),
    (400, "hit 1.5 0.5 20", None, "hit 1.5 0.5 20")]
twins, push = [], p.obj("sig~")
for name, first in [("extra-drum", "contact~ nowhere-drum"), ("twin-drum", "contact~ twin-drum wood")]:
    drum = p.obj("membrane~ %s" % name)
    p.connect(push, 0, drum, 0)
    twins.append((drum, p.obj(first), p.obj("print %s-report" % name)))
    p.connect(twins[-1][1], 1, twins[-1][2], 0)
# A strike, and 0.35 ms later a hit at the same point: the head there comes at the
# stick faster than the hit (2 m/s), and draws back before the stick reaches it. A
# second hit, 300 ms later, touches.
moving = p.obj("membrane~ moving-drum")
moving_con = p.obj("contact~ moving-drum")
p.connect(moving_con, 1, p.obj("print moving-report"), 0)
moving_cases = [(10, moving, "strike 0.3 0 0.05"), (10.35, moving_con, "hit 2 0.3 0"),
                (310, moving_con, "hit 2 0.3 0")]
trig = recorder(p, [(mem, 0, "left"), (mem, 1, "right"), (con, 0, "force"),
                    (twins[0][0], 0, "extra"), (twins[1][0], 0, "twin"),
                    (moving_con, 0, "moving")], 0.8, sr, wav)
for t, extra_text, _, twin_text in extra_cases:
    for (drum, _, _), text in zip(twins, [extra_text, twin_text]):
        d = p.obj("delay %g" % t)
        m = p.msg(text)
        p.connect(trig, 0, d, 0)
        p.connect(d, 0, m, 0)
        p.connect(m, 0, drum, 0)
for t, value in [(60, 0.01), (70, 0)]:
    d = p.obj("delay %g" % t)
    m = p.msg("%g" % value)
    p.connect(trig, 0, d, 0)
    p.connect(d, 0, m, 0)
    p.connect(m, 0, push, 0)
for t, extra_text, _, twin_text in extra_contact_cases:
    for (_, c, _), text in zip(twins, [extra_text, twin_text]):
        if text:
            d = p.obj("delay %g" % t)
            m = p.msg(text)
            p.connect(trig, 0, d, 0)
            p.connect(d, 0, m, 0)
            p.connect(m, 0, c, 0)
for t, target, text in moving_cases:
    d = p.obj("delay %g" % t)
    m = p.msg(text)
    p.connect(trig, 0, d, 0)
    p.connect(d, 0, m, 0)
    p.connect(m, 0, target, 0)
for k, (text, _) in enumerate(membrane_cases):
    d = p.obj("delay %g" % (5 + 3 * k))
    m = p.msg(text)
    p.connect(trig, 0, d, 0)
    p.connect(d, 0, m, 0)
    p.connect(m, 0, mem, 0)
# every message lands before the recording ends (0.8 s)
assert 150 + 20 * len(contact_cases) < 800
for k, (text, _) in enumerate(contact_cases):
    d = p.obj("delay %g" % (150 + 20 * k))
    m = p.msg(text)
    p.connect(trig, 0, d, 0)
    p.connect(d, 0, m, 0)
    p.connect(m, 0, con, 0)
# A membrane~ takes four contact~s: a fifth is silent, and says so when it is hit too.
full = p.obj("membrane~ full-drum")
extra = [p.obj("contact~ full-drum") for _ in range(5)]
# ictus-drum: a lone number or a bang is not a strike; a hand out of 0..3 is refused.
drum = p.obj("ictus-drum")
drum_cases = [("3", "ictus-drum: expected a list <hand> <velocity m/s> <r/a> <theta deg> - got: 3"),
              ("bang", "ictus-drum: expected a list <hand> <velocity m/s> <r/a> <theta deg> - got: "
                       "bang"),
              ("5 3 0.3 0", "ictus-drum: hand must be 0 (left) 1 (right) 2 (right foot) or 3 (left "
                            "foot) - got: 5 3 0.3 0"),
              # a negative stick mass: refused by the hand's contact~ (docs/pd-osc.md)
              ("0 3 0.3 0 -0.02", "contact~: hit: stick mass must be >= 0 kg (0: unchanged), got "
                                  "-0.02; the stick keeps its mass")]
d = p.obj("delay 20")
p.connect(trig, 0, d, 0)
for c in extra:
    m = p.msg("hit 1 0.3 0")
    p.connect(d, 0, m, 0)
    p.connect(m, 0, c, 0)
for text, _ in drum_cases:
    m = p.msg(text)
    p.connect(d, 0, m, 0)
    p.connect(m, 0, drum, 0)
rc, log = run_pd(p.text(), args.build, sr=sr, workdir=work)
print(log)
check(rc == 0, "pd did not crash (exit %d)" % rc)
for text, expect in membrane_cases + contact_cases:
    if expect:
        check(expect in log, "'%s' -> '%s'" % (text, expect))
for text, expect in drum_cases:
    check(expect in log, "ictus-drum '%s' -> '%s'" % (text, expect))
check("membrane~: no method for 'bang'" not in log, "ictus-drum passes no bang to its membrane~")
silent = "contact~: hit: membrane~ 'full-drum' already has 4 contact~s; this one is silent: ignored"
check(log.count(silent) == 1, "the fifth contact~ says its hit is ignored, once (%d)" % log.count(silent))
for bound in ["0.0001", "10"]:  # a bound is not out of bounds
    refused = "stick mass must be in [0.0001, 10] kg, got %s;" % bound
    check(refused not in log, "no error '%s'" % refused)
for expect in ["membrane~: radius must be in [0.01, 2] m, got 1e+30; using 2",
               "membrane~: tension must be in [1, 100000] N/m, got -5; using 1",
               "membrane~: creation argument: density must be a number, got 'nan'",
               "contact~: needs the name of a membrane~",
               "contact~: no membrane~ named 'no-such-drum'",
               "contact~: tip: no stick tip named 'granite' (wood, nylon, felt)"]:
    check(expect in log, "creation: '%s'" % expect)
check("bad arguments for message" not in log, "every message gets the object's own error")
for _, _, expect, _ in extra_cases + extra_contact_cases:
    if expect:
        check(expect in log, "extra-drum: '%s'" % expect)
x, _ = read_wav_float(wav)
check(np.all(np.isfinite(x)), "output finite (%d samples)" % x.shape[0])
check(np.max(np.abs(x[:, 0])) > 0 and np.max(x[:, 2]) > 0,
      "the good strike and hit still sound after the bad ones")
# The extra arguments were left out, the rest was used: the twins sound alike, silent
# until the force at the position.
extra, twin = x[:, 3], x[:, 4]
check(np.array_equal(extra, twin), "extra-drum sounds as twin-drum (largest difference %g)"
      % np.max(np.abs(extra - twin)))
check(np.max(np.abs(extra[:int(0.06 * sr)])) == 0 and np.max(np.abs(extra)) > 0,
      "extra-drum is silent until the force at its position, then sounds")
reports = {}
for name in ["extra-drum", "twin-drum", "moving"]:
    reports[name] = [l.split(":", 1)[1].split() for l in log.splitlines()
                     if l.startswith("%s-report:" % name)]
check(len(reports["extra-drum"]) == 1 and reports["extra-drum"] == reports["twin-drum"],
      "the twins' sticks report alike, once (%s, %s)" % (reports["extra-drum"],
                                                         reports["twin-drum"]))
# The hit on the moving head: no force until the second hit, and no report for it;
# the second hit's report is its force outlet's.
force = x[:, 5].astype(np.float64)
second = int(round(0.310 * sr))
check(np.all(force[:second] == 0), "the hit on the moving head never touches (largest force "
      "%g N before the second hit)" % np.max(force[:second]))
check(len(reports["moving"]) == 1, "only the hit that touched reports (%s)" % reports["moving"])
if len(reports["moving"]) == 1:
    duration_ms, peak_n, rebound_mps = (float(v) for v in reports["moving"][0])
    touching_ms = np.count_nonzero(force[second:]) * 1000.0 / sr
    check(abs(duration_ms - touching_ms) <= 2000.0 / sr,
          "the second hit's duration %g ms is its force's (%g ms)" % (duration_ms, touching_ms))
    check(abs(peak_n - np.max(force)) <= 1e-5 * np.max(force),
          "the second hit's peak %g N is its force's (%g N)" % (peak_n, np.max(force)))
    check(0 < rebound_mps < 2.0, "the second hit's stick leaves slower than it came (%g m/s)"
          % rebound_mps)
