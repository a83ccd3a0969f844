#!/usr/bin/env python3
"""The whole kit's acceptance, measured: a song's drum part through the real `ictusd render
--kit full --midi`:
16 bars at 120 bpm written here as a Standard MIDI File (mido, an independent writer), seeded:

  bars 1-7   an 8th-note closed hi-hat (42), the snare (38) on 2 and 4, the kick (36) on 1 and
             3 and on seeded 8ths, an open hi-hat (46) on the "and" of 4 of a seeded bar;
  bar 8      the groove's first half, then a tom fill of 16ths over beats 3 and 4 (48, 47, 43
             in a seeded order, high to low);
  bars 9-15  a crash (49) with the kick on the downbeat, then the ride (51) on 8ths, the snare
             and the hi-hat's pedal (44, the left foot's chick) on 2 and 4, the kick on 1 and 3;
             on half the seeds that snare is a side stick (37, a cross-stick on the rim);
  bar 16     the groove again, and a last crash with the kick on the next downbeat.

With --downbeat-ride the ride plays bar 9's downbeat too, with the crash: the right hand comes
to it from the fill's last floor tom, 0.37 m in one 16th (docs/score.md, "Rehearsal").

Every note must be one primary strike of its instrument within +-5 ms of its time: notes.csv
matches each note to a strike (docs/midi.md); a note counts as found when its strike is
primary, on the note's drum and within 5 ms. Precision is found notes over primary strikes,
recall found notes over notes, F1 their harmonic mean, reported with the worst error and
asserted 1.0. The hi-hat's and the ride's notes are the right hand's, the snare's under them
the left's (crossed over the hi-hat); the crash's are the left's; the kicks the right foot's,
the chicks the left foot's.
No stick part may go through a drum or cymbal (render.json's `shell_passes` 0), nor a limb
through a drum, a cymbal or a stand (performance.bvh read by ictus_tools.limb_clearance: no
limb's core, its bones, palm or grip, inside a piece; the clearance of its volume printed);
the left foot presses the hi-hat's footboard for each chick. Each
check prints ok or FAIL, every one of them for every seed; the exit status is 1 when any
fails. CTest `perform_song` plays seeds 1–7 and 16 (docs/kit.md, "The song").

    PYTHONPATH=python python3 tests/perform/test_song.py --ictusd build/ictusd --workdir /tmp/song \
        --seed 1 2 3 4 5 6 7 16
"""
import argparse
import json
import math
import os
import random
import subprocess
import tempfile
import sys

import numpy as np

from ictus_tools import e2e_util
from ictus_tools import checks
from ictus_tools import limb_clearance
from ictus_tools.checks import check

mido = e2e_util.require_mido()

TOL_MS = 5.0
HANDS = {"left": 0, "right": 1, "right-foot": 2, "left-foot": 3}


def song(path, rng, downbeat_ride=False):
    """The 16 bars (tpq 480, 120 bpm): the notes as (tick, note, velocity)."""
    tpq, e8, e16 = 480, 240, 120
    bar = 8 * e8
    notes = []
    open_bar = rng.randrange(1, 7)
    fill = [rng.choice((48, 48, 47)) for _ in range(3)] + [47, 47] + [43] * 3

    def groove(b, eighths, timekeeper):
        for k in eighths:
            t = b * bar + k * e8
            if timekeeper == 42 and b == open_bar and k == 7:
                notes.append((t, 46, rng.randint(80, 100)))
            else:
                notes.append((t, timekeeper, rng.randint(60, 100)))
            if k in (2, 6):
                notes.append((t, 38, rng.randint(85, 115)))
            if k in (0, 4) or (k not in (2, 6) and rng.random() < 0.3):
                notes.append((t, 36, rng.randint(70, 120)))
            if timekeeper == 51 and k in (2, 6):
                notes.append((t, 44, rng.randint(60, 100)))

    for b in range(7):
        groove(b, range(8), 42)
    groove(7, range(4), 42)
    for k, tom in enumerate(fill):
        notes.append((7 * bar + 4 * e8 + k * e16, tom, rng.randint(90, 115)))
    notes.append((7 * bar + 4 * e8, 36, 100))
    for b in range(8, 15):
        if b == 8:
            notes.append((b * bar, 49, rng.randint(110, 127)))
            notes.append((b * bar, 36, 120))
            groove(b, range(1, 8), 51)
            if downbeat_ride:
                notes.append((b * bar, 51, 90))
        else:
            groove(b, range(8), 51)
    groove(15, range(8), 42)
    notes.append((16 * bar, 49, 120))
    notes.append((16 * bar, 36, 110))
    if rng.random() < 0.5:  # the ride section's backbeat as a cross-stick: side stick 37
        notes = [(t, 37 if n == 38 and 8 * bar <= t < 15 * bar else n, v) for t, n, v in notes]
    e2e_util.write_drum_midi(mido, path, notes, 120.0, tpq)
    return notes


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ictusd", required=True)
    ap.add_argument("--workdir", default=None, help="where the renders go (default: a new "
                    "temporary folder)")
    ap.add_argument("--seed", type=int, nargs="+", default=[16],
                    help="the songs' seeds, one render each (default 16)")
    ap.add_argument("--render-arg", action="append", default=[],
                    help="an argument more for `ictusd render` (repeat it), e.g. --render-arg=--grip "
                    "--render-arg=german")
    ap.add_argument("--downbeat-ride", action="store_true",
                    help="the ride on the first crash's downbeat too")
    args = ap.parse_args()
    checks.keep_going()  # every check is printed, for every seed
    workdir = args.workdir or tempfile.mkdtemp(prefix="ictus-song-")
    status = 0
    for seed in args.seed:
        print("seed %d:" % seed)
        status |= play(args.ictusd, os.path.join(workdir, "seed-%d" % seed), seed,
                       args.render_arg, args.downbeat_ride)
    return status


def play(ictusd, workdir, seed, render_args, downbeat_ride=False):
    """The song of `seed` rendered in workdir and checked; 1 when the render failed."""
    os.makedirs(workdir, exist_ok=True)
    rng = random.Random(seed)
    part = os.path.join(workdir, "song.mid")
    written = song(part, rng, downbeat_ride)
    out = os.path.join(workdir, "song")
    env = e2e_util.pd_spawning_env(os.path.abspath(workdir))
    run = subprocess.run([ictusd, "render", "--kit", "full", "--midi", part, "--out", out,
                          "--force"] + render_args, capture_output=True, text=True, timeout=900,
                         env=env)
    if not check(run.returncode == 0, "ictusd render --kit full --midi: exit %d %s"
                 % (run.returncode, run.stderr[-2000:])):
        return 1
    check("left out" not in run.stderr, "no note left out: %s" % run.stderr[-500:])
    rj, names, notes, by_seq = e2e_util.read_kit_render(out)
    strikes = list(by_seq.values())
    primary = [s for s in strikes if s["bounce"] == 0]
    check(len(notes) == len(written), "notes.csv: every note of the file: %d of %d"
          % (len(notes), len(written)))
    # Its times are the file's (120 bpm, tpq 480) after one lead-in, whatever a rehearsal
    # planned: each note's error below is its strike's time less that.
    file_s = sorted(tick * 0.5 / 480 for tick, _, _ in written)
    csv_s = sorted(float(n["time_s"]) for n in notes)
    if len(file_s) == len(csv_s):
        off = [c - f for c, f in zip(csv_s, file_s)]
        check(max(off) - min(off) < 2e-6 and abs(off[0] - 1.0) < 2e-6,
              "notes.csv's times are the file's after the 1 s lead-in: %.6f .. %.6f s"
              % (min(off), max(off)))

    found, errors, wrong = 0, [], []
    by_drum = {}
    for n in notes:
        if e2e_util.note_found(n, by_seq, names, TOL_MS, HANDS[n["hand"]]):
            found += 1
            errors.append(float(n["error_ms"]))
            by_drum.setdefault(n["drum"], []).append(float(n["error_ms"]))
        else:
            wrong.append((n["time_s"], n["hand"], n["drum"], n["strike_seq"], n["error_ms"]))
    precision = found / len(primary) if primary else 0.0
    recall = found / len(notes) if notes else 0.0
    f1 = 2 * precision * recall / (precision + recall) if found else 0.0
    worst = max(abs(e) for e in errors) if errors else float("nan")
    rehearsal = rj["performance"].get("rehearsal", {})
    print("rehearsal: %s" % rehearsal)
    print("song: %d notes, %d primary strikes, %d found within %.0f ms: precision %.3f, recall "
          "%.3f, F1 %.3f, worst error %.2f ms" % (len(notes), len(primary), found, TOL_MS,
                                                  precision, recall, f1, worst))
    for d in sorted(by_drum):
        e = by_drum[d]
        print("  %-6s %3d notes, error %+.2f .. %+.2f ms" % (d, len(e), min(e), max(e)))
    check(rj["kit"].get("shell_passes") == 0, "no stick part through a drum or cymbal "
          "(render.json shell_passes): %s" % rj["kit"].get("shell_passes"))
    check(not wrong, "every note one primary strike of its instrument and limb within %.0f ms: "
          "%d not: %s" % (TOL_MS, len(wrong), wrong[:6]))
    check(f1 == 1.0, "F1 at +-%.0f ms is 1.0: %.3f" % (TOL_MS, f1))
    # Sticking: the time-keeper's notes are the right hand's, the snare under them the left's;
    # the crash the left's; the kick the right foot's.
    hand_of = {}
    for n in notes:
        hand_of.setdefault(n["drum"], set()).add(n["hand"])
    check(hand_of.get("hihat") == {"right", "left-foot"} and hand_of.get("ride") == {"right"},
          "hi-hat and ride by the right hand (and the chicks by the left foot): %s" % hand_of)
    check(hand_of.get("snare") == {"left"}, "the snare by the left hand (crossed under the "
          "hi-hat): %s" % hand_of.get("snare"))
    check(hand_of.get("crash") == {"left"}, "the crash by the left hand: %s" % hand_of.get("crash"))
    check(hand_of.get("kick") == {"right-foot"}, "the kick by the right foot: %s"
          % hand_of.get("kick"))
    chicks = [n for n in notes if n["hand"] == "left-foot"]
    check(len(chicks) == sum(1 for _, note, _ in written if note == 44)
          and all(n["drum"] == "hihat" for n in chicks),
          "every pedal hi-hat (44) the left foot's chick on the hi-hat: %d" % len(chicks))
    # The side sticks: the snare's notes at the 37s' times (120 bpm, tpq 480, after the lead-in).
    plan = rj["performance"]["plan"]
    side_ms = {round(1e3 * (plan["origin_s"] + plan["lead_in_s"]) + t / 480 * 500.0)
               for t, note, _ in written if note == 37}
    zones = [by_seq[int(n["strike_seq"])]["zone"] if int(n["strike_seq"]) in by_seq else None
             for n in notes if n["drum"] == "snare" and round(1e3 * float(n["time_s"])) in side_ms]
    others = [by_seq[int(n["strike_seq"])]["zone"] for n in notes if n["drum"] == "snare"
              and round(1e3 * float(n["time_s"])) not in side_ms and int(n["strike_seq"]) in by_seq]
    check(len(zones) == len(side_ms) and all(z == 1 for z in zones) and all(z == 0 for z in others),
          "every side stick (37) on the snare's rim (zone 1), every other snare note on its head: "
          "%d side sticks, zones %s; heads %s" % (len(side_ms), sorted(set(map(str, zones))),
                                                  sorted(set(others))))
    check_body(out, strikes)
    return 0


def foot_pitch(pos, index, side, rest_frame):
    """The foot's toe-down turn from its pose at rest_frame (rad), each frame: the angle of
    the ankle-to-toe vector from its rest direction."""
    v = pos[:, index[side + "ToeBase"]] - pos[:, index[side + "Foot"]]
    v0 = v[rest_frame]
    c = (v @ v0) / (np.linalg.norm(v, axis=1) * np.linalg.norm(v0))
    return np.arccos(np.clip(c, -1.0, 1.0))


def check_body(out, strikes):
    """The performer's body from performance.bvh (its own forward kinematics,
    ictus_tools.limb_clearance): no limb through a piece, and the left foot on the hi-hat's
    pedal."""
    bvh = limb_clearance.Bvh(os.path.join(out, "performance.bvh"))
    pos = bvh.positions()
    index = {n: i for i, n in enumerate(bvh.names)}
    # The reading checked against the physics' strikes: at each primary strike of a hand, the
    # stick's end (the BVH's end site) on its head at the struck radius, within the bead's
    # size (15 mm) and the 2 ms a 250 Hz frame may be off the strike.
    with open(os.path.join(out, "render.json")) as f:
        drums = json.load(f)["kit"]["drums"]
    last = pos.shape[0] - 1

    def frame(t):
        return min(max(int(round(t / bvh.frame_time_s)), 0), last)

    off = []
    for s in strikes:
        if s["hand"] in (HANDS["left"], HANDS["right"]) and s["bounce"] == 0:
            f = frame(s["time_s"])
            end = pos[f, index[("Left" if s["hand"] == 0 else "Right") + "HandStick_End"]]
            d = drums[s["drum"]]
            rel = end - np.array(d["center_m"])
            reach = 0.015 + 0.002 * math.hypot(s["normal_velocity_mps"],
                                               s["tangential_velocity_mps"])
            if abs(rel[1]) > reach or abs(math.hypot(rel[0], rel[2]) - s["r_over_a"] *
                                          d["radius_m"]) > reach:
                off.append((s["seq"], d["name"], rel.round(4).tolist()))
    check(not off, "performance.bvh's sticks on their heads at the strikes: %d off %s"
          % (len(off), off[:4]))
    c = limb_clearance.clearances(out, bvh, pos)
    core = min(c.items(), key=lambda kv: kv[1].core_m)
    volume = min(c.items(), key=lambda kv: kv[1].volume_m)
    print("  limbs: least clearance of a limb's core (bones, palm, grip) %.1f mm (%s to %s at "
          "%.3f s); of its volume %.1f mm (%s to %s at %.3f s)"
          % (1e3 * core[1].core_m, core[0][0], core[0][1], core[1].time_s,
             1e3 * volume[1].volume_m, volume[0][0], volume[0][1], volume[1].time_s))
    check(core[1].core_m > 0.0, "no limb through a drum, a cymbal or a stand (its core "
          "outside every piece): %.1f mm" % (1e3 * core[1].core_m))
    # The left foot presses the hi-hat's footboard for each chick: the plates meet when the
    # rod has come down the 15 mm gap, 3 x 0.1 m of lever per footboard radian (docs/pedal.md:
    # a footboard angle of 0.05 rad); before the stroke (0.2 s, longer than its 0.12 s) the
    # foot rests.
    first = min(s["time_s"] for s in strikes)
    pitch = foot_pitch(pos, index, "Left", int(0.5 * first / bvh.frame_time_s))
    closed = 0.015 / (3.0 * 0.1)
    at, before = [], []
    for s in strikes:
        if s["hand"] == HANDS["left-foot"] and s["bounce"] == 0 and s["time_s"] >= 0.2:
            at.append(pitch[frame(s["time_s"])])
            before.append(pitch[frame(s["time_s"] - 0.2)])
    if not check(at, "the song's chicks are in strikes.csv"):
        return
    print("  left foot at the chicks: toe down %.4f .. %.4f rad (the plates meet at %.4f), "
          "0.2 s before %.4f .. %.4f" % (min(at), max(at), closed, min(before), max(before)))
    check(all(0.5 * closed <= a <= 1.05 * closed for a in at) and max(before) < 0.1 * closed,
          "the left foot presses the hi-hat's footboard at each chick and rests before it")
    # The feet stay on their pedals (docs/kit.md, "The throne"): the kick's batter 0.27 m
    # before the right ankle and in line with it, the hi-hat's rod 0.2-0.3 m before the left
    # and within 0.1 m of it across, the ankles 8 cm up; an ankle only turns, so it stays put.
    kick = next(d for d in drums if d["name"] == "kick")
    hat = next(d for d in drums if d["name"] == "hihat")
    right, left = pos[:, index["RightFoot"]], pos[:, index["LeftFoot"]]
    drift = max(np.abs(right - right[0]).max(), np.abs(left - left[0]).max())
    r0, l0 = right[0], left[0]
    print("  ankles: right %s, left %s, moved at most %.2f mm; the kick's batter %s, the hi-hat "
          "%s" % (r0.round(3), l0.round(3), 1e3 * drift, np.round(kick["center_m"], 3),
                  np.round(hat["center_m"], 3)))
    check(drift < 1e-3 and abs(kick["center_m"][2] - r0[2] - 0.27) < 0.005
          and abs(kick["center_m"][0] - r0[0]) < 0.005 and abs(r0[1] - 0.08) < 0.005
          and 0.2 < hat["center_m"][2] - l0[2] < 0.3 and abs(hat["center_m"][0] - l0[0]) < 0.1
          and abs(l0[1] - 0.08) < 0.005,
          "the feet stay on their pedals: the right ankle 0.27 m behind the kick's batter, the "
          "left 0.2-0.3 m behind the hi-hat's rod, both 8 cm up, neither moving")


if __name__ == "__main__":
    status = main()
    if status:
        sys.exit(status)
    checks.finish()
