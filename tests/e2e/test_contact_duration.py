"""The sound's contact lasts as long as the physics' (docs/sound.md, "Contact
duration: the sound's stick against the physics'"): through the real pd in batch
mode (patches/ictus-render.pd, its render-reports file: contact~'s duration of
every stroke), the sound's contact durations are within 25 % of the physics'.
Three parts (--part):

law    synthetic events files, no daemon: sticks of 0.01-0.05 kg at 0.5-10 m/s
       (each line carrying its stick_mass_kg, as ictusd writes them) on the
       physics' default drum (render.json's: radius 0.178 m, tension 3000 N/m,
       density 0.26 kg/m^2), against the duration of the physics' contact law
       integrated here: the bead of mass m lands at v0 on the spring-damper
       F = max(0, k d + k3 d^3 + c d') (docs/osc.md, k = 2 pi T / ln(R / r_tip),
       r_tip 7 mm, k3 the head's stretching (docs/contact.md, "Stick tips"), c the
       drum's contact damping, a massless head; the integrator is checked
       against the closed form of k3 = 0), the bead then flies free and the
       contact ends when it is back at the membrane plane, which is where the
       strike detector ends it (its duration_ms: onset to release, "release" =
       the bead above the plane). Also the dynamics ladder's seeded speeds: the
       log-log slope of contact~'s durations against speed is the law's.
       PER STRIKE: here the physics is exactly a free bead of the strike's
       mass, which is what contact~ is given, so every stroke must agree.

ladder `ictusd render --drum-preset tom` plays the dynamics ladder R legato 0.1 .. 1.0
       (tempo 30, as e2e_expression): render.json's head stretching is the
       Begley & Mackin k3 of the tom's film computed here (0.491 kg/m^2 of Mylar,
       a 0.1524 m); every note's contact~ duration within 25 % of the physics'
       (PER STRIKE), and the log-log slope of duration against impact speed
       <= -0.1 for the law (integrated here), the physics and contact~. In a
       sanitizer build the ladder is 0.1, 0.4, 0.7, 1.0 (time).

score  `ictusd render` plays the default score; its strikes.csv holds the
       physics' duration and stick mass of every strike; the events file is
       rendered on render.json's drum (as scripts/main.sh does) and every
       strike's report is matched to it. THE MEDIAN over the strikes of
       |d_pd - d_physics| / d_physics: in the physics the stick stays on its
       fulcrum and the hand keeps moving during the contact (pressed strokes
       and bounces: 12-26 ms where a free bead of their mass stays 5 ms), and
       its 1 ms step stretches the contact, none of which the strike carries
       or contact~, a free stick from the onset on, can play; the per-strike
       errors are printed
       (docs/sound.md has them). Every primary strike must have a report; a
       bounce may have none when the next contact of its hand came before
       contact~'s stick was clear (the sound then plays both as one stroke).
       Also checks that render.json's contact law is the one the law part
       uses. Skipped (exit 77) while the daemon writes no stick mass. In a
       sanitizer build only the score's first 6 s are played (time).

Each report is matched to its strike by hand and time: a contact~ reports when
its stick is clear of the head, so a report belongs to the latest strike of its
hand before it."""
import argparse
import csv
import json
import math
import os
import subprocess
import sys

import numpy as np

from ictus_tools import e2e_util as u
from ictus_tools.checks import check
from ictus_tools.pdrun import error_lines, make_workdir

BOUND = 0.25           # |d_pd - d_physics| / d_physics: per strike (law), median (score)
TIP_RADIUS_M = 0.007   # the bead (daemon: StrikeDetectorOptions::tip_radius_m, docs/osc.md)
# the physics' default drum (DrumParams in daemon/include/ictus/sim/scene.hpp, as
# render.json reports it; the score part checks that they still agree)
DRUM = {"radius_m": 0.178, "tension_n_per_m": 3000.0, "density_kg_per_m2": 0.26,
        "contact_damping_n_s_per_m": 3.0}

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
ap.add_argument("--part", choices=("law", "ladder", "score"), required=True)
args = ap.parse_args()
build = os.path.abspath(args.build)
work = make_workdir("ictus-e2e-contact-")


def physics_duration_ms(m, k, c):
    """Onset to release of a bead of mass m (kg) landing on F = max(0, k d + c d')
    (k N/m, c N s/m) with a massless head: d = v0/wd e^(-z w0 t) sin(wd t) while
    F > 0; F = k d + c d' = v0 e^(-z w0 t) (A sin(wd t) + c cos(wd t)) with
    A = (k - c^2 / (2 m)) / wd is 0 first at wd t_f = pi - atan2(c, A); then
    the bead moves at d'(t_f) < 0 with no force and is back at d = 0 after
    d(t_f) / -d'(t_f). Independent of v0 (linear)."""
    w0 = math.sqrt(k / m)
    z = c / (2.0 * math.sqrt(k * m))
    if not z < 1.0:
        raise ValueError("overdamped contact (m %g kg): not a stroke" % m)
    wd = w0 * math.sqrt(1.0 - z * z)
    a = (k - c * c / (2.0 * m)) / wd
    t_f = (math.pi - math.atan2(c, a)) / wd
    decay = math.exp(-z * w0 * t_f)
    d = decay * math.sin(wd * t_f) / wd                                # per unit v0
    v = decay * (math.cos(wd * t_f) - z * w0 / wd * math.sin(wd * t_f))  # per unit v0
    return (t_f + d / -v) * 1e3


# The head's stretching under the stick (docs/contact.md, "Stick tips"): F = k d + K3 d^3,
# K3 = E h q^3 / a^2, q = 1 / (1.05 - 0.15 nu - 0.16 nu^2) (Begley & Mackin 2004), for
# the default Mylar head: E 4.5 GPa, nu 0.38, h = 0.262 kg/m^2 / 1390 kg/m^3, a 0.178 m.
_Q = 1.0 / (1.05 - 0.15 * 0.38 - 0.16 * 0.38 ** 2)
K3 = 4.5e9 * (0.262 / 1390.0) * _Q ** 3 / 0.178 ** 2
# The tom preset's head (membrane_presets.c: a 12-inch two-ply Mylar batter, 2 x 0.178 mm,
# at 1465.7 N/m).
TOM = {"radius_m": 0.1524, "tension_n_per_m": 1465.7, "density_kg_per_m2": 0.491}
K3_TOM = 4.5e9 * (TOM["density_kg_per_m2"] / 1390.0) * _Q ** 3 / TOM["radius_m"] ** 2


def stretched_duration_ms(m, k, c, k3, v0, dt=1e-6):
    """The same bead on F = max(0, k d + k3 d^3 + c d') landing at v0, integrated
    (RK4, dt s) to its return to the plane (interpolated)."""
    def acc(d, dd):
        f = k * d + k3 * d ** 3 + c * dd
        return -f / m if d > 0.0 and f > 0.0 else 0.0
    d, dd, t = 0.0, v0, 0.0
    while t < 0.2:
        a1 = acc(d, dd)
        a2 = acc(d + 0.5 * dt * dd, dd + 0.5 * dt * a1)
        a3 = acc(d + 0.5 * dt * (dd + 0.5 * dt * a1), dd + 0.5 * dt * a2)
        a4 = acc(d + dt * (dd + 0.5 * dt * a2), dd + dt * a3)
        d1 = d + dt * dd + dt * dt / 6.0 * (a1 + a2 + a3)
        dd1 = dd + dt / 6.0 * (a1 + 2 * a2 + 2 * a3 + a4)
        if t > 0.0 and d1 < 0.0:
            return (t + dt * d / (d - d1)) * 1e3
        d, dd, t = d1, dd1, t + dt
    raise ValueError("no release within 0.2 s (m %g kg, v0 %g m/s)" % (m, v0))


def force_zero_ms(m, k, c):
    """t_f alone (the force's half-period), for the report."""
    w0 = math.sqrt(k / m)
    z = c / (2.0 * math.sqrt(k * m))
    wd = w0 * math.sqrt(1.0 - z * z)
    return (math.pi - math.atan2(c, (k - c * c / (2.0 * m)) / wd)) / wd * 1e3


def read_reports(path):
    """render-reports file -> [(time_ms, hand, duration_ms, peak_force_n, rebound_mps)]."""
    with open(path) as f:
        text = f.read()
    rows = []
    for n, raw in enumerate(text.split(";"), start=1):
        words = raw.split()
        if not words:
            continue
        if len(words) != 5:
            raise ValueError("%s: report %d has %d numbers, expected 5" % (path, n, len(words)))
        t, hand, dur, peak, reb = (float(w) for w in words)
        rows.append((t, int(hand), dur, peak, reb))
    return rows


def match_reports(strikes_t_ms, strikes_hand, reports):
    """Index of the report of each strike (None when it has none): a report goes
    to the latest strike of its hand that started before it."""
    owner, twice, orphans = [None] * len(strikes_t_ms), [], []
    for r, (t, hand, _, _, _) in enumerate(reports):
        before = [i for i in range(len(strikes_t_ms))
                  if strikes_hand[i] == hand and strikes_t_ms[i] < t]
        if not before:
            orphans.append(r)
            continue
        i = max(before, key=lambda j: strikes_t_ms[j])
        if owner[i] is not None:
            twice.append(i)
        owner[i] = r
    check(not twice and not orphans, "at most one report per strike, none before the first "
          "(strikes with two: %s, reports without a strike: %s)" % (twice, orphans))
    return owner


def render_with_reports(events_path, seconds, tag):
    wav = os.path.join(work, "%s.wav" % tag)
    reports = os.path.join(work, "%s-reports.txt" % tag)
    cmd = u.PD_BATCH + ["-r", "48000", "-path", os.path.join(build, "ictus"), "-open",
                        u.RENDER_PATCH, "-send", "render-file %s" % events_path, "-send",
                        "render-out %s" % wav, "-send", "render-seconds %.3f" % seconds, "-send",
                        "render-reports %s" % reports]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=300, env=u.PD_ENV)
    log = proc.stdout + proc.stderr
    check(proc.returncode == 0 and not error_lines(log),
          "ictus-render ran cleanly (%s): %s" % (tag, error_lines(log)))
    check(os.path.isfile(reports), "ictus-render wrote the contact reports (%s)" % tag)
    return read_reports(reports)


def judge(rows, what, per_strike):
    """rows: (label, d_physics_ms, d_pd_ms or None, may_lack_report). Prints them and
    checks the bound: on every strike (per_strike) or on the median."""
    errors = []
    print("%-48s %9s %9s %8s" % ("strike", "physics", "pd", "error"))
    for label, d_phys, d_pd, _ in rows:
        e = None if d_pd is None else (d_pd - d_phys) / d_phys
        errors.append(e)
        print("%-48s %9.3f %9s %8s" % (label, d_phys, "-" if d_pd is None else "%.3f" % d_pd,
                                        "-" if e is None else "%+.1f%%" % (100 * e)))
    missing = [r[0] for r, e in zip(rows, errors) if e is None and not r[3]]
    check(not missing, "%s: every strike that must have a contact~ report has one (missing: %s)"
          % (what, missing))
    signed = np.array([e for e in errors if e is not None])
    rel = np.abs(signed)
    within = int(np.sum(rel <= BOUND))
    print("%s: %d strikes with a report (%d without), |error| median %.1f%%, worst %.1f%%, "
          "signed %+.1f%% .. %+.1f%%, %d of %d within %d%%"
          % (what, len(rel), len(rows) - len(rel), 100 * np.median(rel), 100 * rel.max(),
             100 * signed.min(), 100 * signed.max(), within, len(rel), 100 * BOUND))
    if per_strike:
        worst = int(np.argmax([abs(e) for e in errors]))
        check(rel.max() <= BOUND, "%s: every strike's contact~ duration within %d%% of the "
              "physics' (worst %.1f%%: %s)" % (what, 100 * BOUND, 100 * rel.max(), rows[worst][0]))
    else:
        check(np.median(rel) <= BOUND, "%s: the median strike's contact~ duration within %d%% "
              "of the physics' (median |error| %.1f%%)" % (what, 100 * BOUND,
                                                          100 * np.median(rel)))


def slope(v, d):
    """Log-log slope of durations d against speeds v (least squares)."""
    return float(np.polyfit(np.log(v), np.log(d), 1)[0])


def ladder_part():
    """The dynamics ladder on the tom preset: physics against contact~, per note."""
    ictusd = os.path.join(build, "ictusd")
    check(os.access(ictusd, os.X_OK), "ictusd is built at %s" % ictusd)
    ladder = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0]
    if os.environ.get("ICTUS_PD_PRELOAD"):
        ladder = [0.1, 0.4, 0.7, 1.0]  # the sanitizer build's ictusd runs at ~0.08x real time
        print("sanitizer build: the ladder %s only" % ladder)
    score, out = os.path.join(work, "ladder.score"), os.path.join(work, "ladder")
    with open(score, "w") as f:
        f.write("tempo 30\n" + "".join("R legato %g\n" % d for d in ladder))
    proc = subprocess.run([ictusd, "render", "--score", score, "--out", out, "--drum-preset",
                           "tom", "--bvh-rate", "0", "--tips-rate", "0", "--progress-every", "0"],
                          capture_output=True, text=True, timeout=600)
    check(proc.returncode == 0, "ictusd render (the ladder, tom) ran: %s" % proc.stderr[-2000:])
    with open(os.path.join(out, "render.json")) as f:
        drum = json.load(f)["drum"]
    check(all(abs(drum[key] - TOM[key]) <= 1e-9 * TOM[key] for key in TOM),
          "render.json's drum is the tom (%s)" % TOM)
    check(abs(drum["contact_stretch_n_per_m3"] - K3_TOM) <= 1e-6 * K3_TOM,
          "render.json's head stretching %.4g N/m^3 is Begley & Mackin's for the tom's film, "
          "%.4g" % (drum["contact_stretch_n_per_m3"], K3_TOM))
    strikes = u.read_strikes(os.path.join(out, "strikes.csv"))
    with open(os.path.join(out, "notes.csv")) as f:
        seqs = [int(r["strike_seq"]) for r in csv.DictReader(f)]
    check(len(seqs) == len(ladder), "every note of the ladder has its strike (%d)" % len(seqs))
    path = os.path.join(work, "ladder-events.txt")
    u.write_events(path, u.drum_lines(os.path.join(out, "render.json")),
                   u.read_events(os.path.join(out, "events.txt")))
    reports = render_with_reports(path, strikes[-1]["time_s"] + 0.5, "ladder")
    owner = match_reports([s["time_s"] * 1e3 for s in strikes], [s["hand"] for s in strikes],
                          reports)
    k = 2.0 * math.pi * TOM["tension_n_per_m"] / math.log(TOM["radius_m"] / TIP_RADIUS_M)
    c = drum["contact_damping_n_s_per_m"]
    rows, v, law, pressed = [], [], [], []
    for d, seq in zip(ladder, seqs):
        s = next(x for x in strikes if x["seq"] == seq)
        v.append(s["normal_velocity_mps"])
        law.append(stretched_duration_ms(s["stick_mass_kg"], k, c, K3_TOM, v[-1]))
        r = owner[strikes.index(s)]
        # contact~ strikes a free stick, whose impulse is at most 2 m v (a perfectly elastic
        # bounce); more means the hand pressed the stick into the head during the contact.
        pressed.append(s["impulse_n_s"] > 2.0 * s["stick_mass_kg"] * v[-1])
        rows.append(("legato %.1f: %.4f kg %.2f m/s r/a %.2f (law %.2f)%s"
                     % (d, s["stick_mass_kg"], v[-1], s["r_over_a"], law[-1],
                        " pressed" if pressed[-1] else ""), s["duration_ms"],
                     None if r is None else reports[r][2], False))
    free = [r for r, p in zip(rows, pressed) if not p]
    check(len(free) >= len(rows) - 1, "tom ladder: the hand presses at most the softest stroke "
          "into the head (pressed: %s)" % [r[0] for r, p in zip(rows, pressed) if p])
    judge(free, "tom ladder, free strikes", per_strike=True)
    for r in (r for r, p in zip(rows, pressed) if p):
        check(r[2] is not None and r[1] > r[2], "%s: the press lengthens the physics' contact "
              "beyond the free stick's (%.2f ms against contact~ %s ms)" % (r[0], r[1], r[2]))
    if any(r[2] is None for r in rows):
        return
    vf = [x for x, p in zip(v, pressed) if not p]
    slopes = {"the law": slope(v, law), "contact~": slope(v, [r[2] for r in rows])}
    for who, sl in slopes.items():
        print("tom ladder %.2f..%.2f m/s: log-log slope of %s %.3f" % (v[0], v[-1], who, sl))
        # The law is no power law (the stretching takes over at speed): its slope is held
        # over the whole ladder; the sanitizer build's four steps weigh the slow end more
        # (-0.099 there against -0.112), so there it is printed only.
        if who == "the law" and len(ladder) < 10:
            continue
        check(sl <= -0.1, "tom ladder: the contact of %s shortens with speed, slope %.3f <= -0.1"
              % (who, sl))
    # The physics' own slope over the free strikes, held as the law's is (over the whole
    # ladder): the strike aim's cap keeps the hand from following through into the head,
    # which lengthened the loud contacts (docs/contact.md).
    sl = slope(vf, [r[1] for r in free])
    print("tom ladder %.2f..%.2f m/s, free strikes: log-log slope of the physics %.3f"
          % (vf[0], vf[-1], sl))
    if len(ladder) >= 10:
        check(sl <= -0.1, "tom ladder: the physics' contact shortens with speed, slope %.3f "
              "<= -0.1" % sl)


if args.part == "law":
    k = 2.0 * math.pi * DRUM["tension_n_per_m"] / math.log(DRUM["radius_m"] / TIP_RADIUS_M)
    c = DRUM["contact_damping_n_s_per_m"]
    print("physics' contact: k = 2 pi T / ln(R / r_tip) = %.1f N/m, k3 = %.3g N/m^3, "
          "c = %g N s/m" % (k, K3, c))
    # The integrator against Hertz's law for a power-law contact F = K d^alpha: the
    # duration goes as v^(-(alpha - 1) / (alpha + 1)), -0.5 for the stretching alone
    # (alpha 3), at any pair of speeds.
    s_cubic = math.log(stretched_duration_ms(0.0136, 0.0, 0.0, K3, 8.0, 1e-7) /
                       stretched_duration_ms(0.0136, 0.0, 0.0, K3, 2.0, 1e-7)) / math.log(4.0)
    check(abs(s_cubic + 0.5) <= 1e-3, "RK4 of F = k3 d^3 alone: log-log slope %.4f = "
          "-(3 - 1) / (3 + 1)" % s_cubic)
    # The integrator against the closed form of the linear law.
    for m in (0.01, 0.05):
        lin, num = physics_duration_ms(m, k, c), stretched_duration_ms(m, k, c, 0.0, 1.0)
        check(abs(num - lin) <= 1e-3 * lin, "RK4 of the linear law %.4f ms = closed form "
              "%.4f ms (%g kg)" % (num, lin, m))
    masses = (0.01, 0.02, 0.03, 0.05)
    velocities = (0.5, 1.0, 2.0, 5.0, 10.0)
    # and the dynamics ladder's speeds (0.24 .. 5.85 m/s, docs/perform.md), seeded: one
    # speed in each of 8 equal bins of log v, for the default score's stick and a heavy one
    rng = np.random.default_rng(7)
    lo, hi = math.log(0.24), math.log(5.85)
    ladder = [math.exp(lo + (j + rng.random()) / 8.0 * (hi - lo)) for j in range(8)]
    plan = [(m, v) for m in masses for v in velocities] + \
        [(m, v) for m in (0.0136, 0.05) for v in ladder]
    # one stroke a second (the head's t60 is 1 s: the previous one is 60 dB down), both
    # hands in turn, where the default score hits (r/a 0.33-0.35) and a little around it
    lines = ["render-drum radius %g" % DRUM["radius_m"],
             "render-drum tension %g" % DRUM["tension_n_per_m"],
             "render-drum density %g" % DRUM["density_kg_per_m2"]]
    events, strikes = ["0 %s;" % l for l in lines], []
    for i, (m, v) in enumerate(plan):
        t_ms = 100.0 + 1000.0 * i
        hand, ra, theta = i % 2, 0.30 + 0.01 * (i % 6), 20.0 * i
        events.append("%.3f hit %d 0 0 %.4f %.5f %.2f 0 0 0 0 %.6f %.5f;"
                      % (100.0 if i == 0 else 1000.0, hand, v, ra, theta, t_ms / 1e3, m))
        strikes.append((t_ms, hand, m, v, ra))
    path = os.path.join(work, "law-events.txt")
    with open(path, "w") as f:
        f.write("\n".join(events) + "\n")
    reports = render_with_reports(path, len(strikes) + 0.5, "law")
    owner = match_reports([s[0] for s in strikes], [s[1] for s in strikes], reports)
    rows = []
    for (t_ms, hand, m, v, ra), r in zip(strikes, owner):
        rows.append(("%.4f kg at %4.2f m/s, r/a %.2f (linear: %.2f ms)"
                     % (m, v, ra, physics_duration_ms(m, k, c)),
                     stretched_duration_ms(m, k, c, K3, v),
                     None if r is None else reports[r][2], False))
    judge(rows, "law", per_strike=True)
    # The ladder: contact~'s log-log slope of duration against speed is the law's
    # (the head's stretching; a linear head gives 0), within 0.02.
    n_grid = len(masses) * len(velocities)
    for m in (0.0136, 0.05):
        idx = [i for i in range(n_grid, len(plan)) if plan[i][0] == m]
        lv = np.log([plan[i][1] for i in idx])
        s_law = np.polyfit(lv, np.log([rows[i][1] for i in idx]), 1)[0]
        s_pd = np.polyfit(lv, np.log([rows[i][2] for i in idx]), 1)[0]
        print("ladder %.4f kg, 0.24..5.85 m/s: log-log slope contact~ %.3f, law %.3f"
              % (m, s_pd, s_law))
        check(s_law < -0.01 and abs(s_pd - s_law) <= 0.02,
              "ladder %.4f kg: contact~'s slope %.3f is the law's %.3f (within 0.02, < 0)"
              % (m, s_pd, s_law))
elif args.part == "ladder":
    ladder_part()
else:
    ictusd = os.path.join(build, "ictusd")
    check(os.access(ictusd, os.X_OK), "ictusd is built at %s" % ictusd)
    out = os.path.join(work, "out")
    render = [ictusd, "render", "--out", out]
    if os.environ.get("ICTUS_PD_PRELOAD"):
        # A sanitizer build (tests/CMakeLists.txt sets ICTUS_PD_PRELOAD there): its
        # ictusd plays the whole score at ~0.08x real time (3.5 min), so it plays
        # the first 6 s (9 strikes, bounces among them); the physics gives the same
        # strikes as the release build's, which measures the whole score.
        render += ["--duration", "6"]
        print("sanitizer build: the default score's first 6 s only")
    proc = subprocess.run(render, capture_output=True, text=True, timeout=600)
    check(proc.returncode == 0, "ictusd render (the default score) ran: %s" % proc.stderr[-2000:])
    strikes = u.read_strikes(os.path.join(out, "strikes.csv"))
    check(len(strikes) >= 8, "the default score gives strikes (%d)" % len(strikes))
    check("stick_mass_kg" in strikes[0], "strikes.csv has the stick_mass_kg column")
    if all(s["stick_mass_kg"] == 0 for s in strikes):
        print("SKIPPED: every strike of the default score has stick_mass_kg 0 (the physics "
              "does not give the stick's mass yet), so the sound plays contact~'s own stick")
        sys.exit(77)
    check(all(s["stick_mass_kg"] > 0 for s in strikes), "every strike carries a stick mass")
    with open(os.path.join(out, "render.json")) as f:
        drum = json.load(f)["drum"]
    k_law = 2.0 * math.pi * DRUM["tension_n_per_m"] / math.log(DRUM["radius_m"] / TIP_RADIUS_M)
    check(all(abs(drum[key] - DRUM[key]) <= 1e-9 * abs(DRUM[key]) for key in DRUM)
          and abs(drum["contact_stiffness_n_per_m"] - k_law) <= 1e-6 * k_law,
          "render.json's drum and contact law are the law part's (%s; k %.3f N/m): if the "
          "physics' defaults changed, update DRUM here" % (DRUM, k_law))
    events = u.read_events(os.path.join(out, "events.txt"))
    header = u.drum_lines(os.path.join(out, "render.json"))
    path = os.path.join(work, "score-events.txt")
    u.write_events(path, header, events)
    seconds = strikes[-1]["time_s"] + 0.5
    reports = render_with_reports(path, seconds, "score")
    owner = match_reports([s["time_s"] * 1e3 for s in strikes], [s["hand"] for s in strikes],
                          reports)
    rows = []
    for s, r in zip(strikes, owner):
        law = physics_duration_ms(s["stick_mass_kg"], drum["contact_stiffness_n_per_m"],
                                  drum["contact_damping_n_s_per_m"])
        rows.append(("%d hand %d%s %.4f kg %.2f m/s r/a %.2f (law %.2f)"
                     % (s["seq"], s["hand"], " bounce" if s["bounce"] else "", s["stick_mass_kg"],
                        s["normal_velocity_mps"], s["r_over_a"], law), s["duration_ms"],
                     None if r is None else reports[r][2], bool(s["bounce"])))
    judge(rows, "default score", per_strike=False)
