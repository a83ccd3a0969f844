#!/usr/bin/env python3
"""The kick of `--kit full`, played by the right foot on its pedal (docs/pedal.md), through the
real `ictusd render --wav`:

1. A drum part written here as a Standard MIDI File (mido, an independent writer): seeded
   random bars of an 8th-note closed hi-hat (42) at a seeded random tempo, the snare (38) on 2
   and 4, and kicks (36, some 35) on seeded random 8ths at seeded random velocities, read by
   `--midi`. Every kick note is one primary strike of the right foot (strikes.csv hand 2) on
   the kick (drum 7, the felt tip: stick_tip 3) within 0.5 ms of its time (the pedal's own
   planning tolerance, docs/pedal.md), no other strike of the foot; strikes.csv is in onset
   order and events.txt's delays are never negative; louder kicks hit faster (every kick of a
   higher velocity at least as fast as every kick of a lower one, the pedal's speed law);
   performance.mid has a note 36 per kick strike; render.json lists the kick, played by the
   right foot; pd.log has no error line. The hands' notes are reported. The example
   examples/scores/groove.txt: every note struck, its kicks within 0.5 ms.
2. A score of kicks alone (`RF` pp .. ff, seeded order): every strike's fundamental, the
   lowest spectral peak 5..65 ms after it, is below 100 Hz; the softest one's is the kick
   head's (0,1) mode j01 / (2 pi a) sqrt(T / sigma) from render.json's head (3 %); it never
   falls as the kicks get faster (the tension modulation raises it, docs/sound.md).

    PYTHONPATH=python python3 tests/perform/test_kick_pedal.py --ictusd build/ictusd
"""
import argparse
import csv
import json
import os
import random
import subprocess
import sys

from ictus_tools import e2e_util
from ictus_tools.checks import check
from ictus_tools.drumtone import f01, lowest_peak_hz

mido = e2e_util.require_mido()

KICK = 7  # its index in `full`
FOOT = 2  # strikes.csv's hand of the right foot
FELT = 3  # strikes.csv's stick_tip of felt


def groove(path, rng):
    """A drum part of 4 bars in 4/4 (tpq 480): 8th hi-hats, snare on 2 and 4, random kicks."""
    tpq = 480
    bpm = rng.uniform(90.0, 130.0)
    events = []  # (tick, note, velocity)
    kicks = []
    for bar in range(4):
        for eighth in range(8):
            tick = (bar * 8 + eighth) * tpq // 2
            events.append((tick, 42, rng.randint(60, 100)))
            if eighth in (2, 6):
                events.append((tick, 38, rng.randint(80, 110)))
            if eighth == 0 or rng.random() < 0.35:
                v = rng.randint(20, 127)
                events.append((tick, rng.choice((35, 36, 36)), v))
                kicks.append((tick, v))
    e2e_util.write_drum_midi(mido, path, events, bpm, tpq)
    return bpm, tpq, kicks


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ictusd", required=True)
    ap.add_argument("--workdir", default="kick-pedal-test")
    ap.add_argument("--seed", type=int, default=36)
    ap.add_argument("--no-scores", action="store_true",
                    help="skip the example and runaway scores (the groove and the kicks alone "
                         "stay): the sanitizer build's run")
    args = ap.parse_args()
    os.makedirs(args.workdir, exist_ok=True)
    rng = random.Random(args.seed)

    # 1. The groove from a MIDI file.
    part = os.path.join(args.workdir, "groove.mid")
    bpm, tpq, kicks = groove(part, rng)
    print("groove: %.1f bpm, %d kicks" % (bpm, len(kicks)))
    out, _ = e2e_util.render_kit(args.ictusd, args.workdir, "groove", "full",
                                 ["--midi", part])
    with open(os.path.join(out, "render.json")) as f:
        rj = json.load(f)
    drums = rj["kit"]["drums"]
    check(len(drums) == 8 and drums[KICK]["name"] == "kick"
          and drums[KICK].get("played_by") == "right foot",
          "render.json: the kick is drum %d, played by the right foot: %s"
          % (KICK, [(d["name"], d.get("played_by")) for d in drums]))
    with open(os.path.join(out, "notes.csv")) as f:
        notes = list(csv.DictReader(f))
    feet = [n for n in notes if n["hand"] == "right-foot"]
    hands = [n for n in notes if n["hand"] != "right-foot"]
    check(len(feet) == len(kicks), "notes.csv: one right-foot note per kick: %d of %d"
          % (len(feet), len(kicks)))
    strikes = e2e_util.read_strikes(os.path.join(out, "strikes.csv"))
    by_seq = {s["seq"]: s for s in strikes}
    errors = []
    for n in feet:
        check(n["drum"] == "kick" and n["strike_seq"] != "-1",
              "kick note at %s s struck on the kick: %s" % (n["time_s"], n["strike_seq"]))
        s = by_seq[int(n["strike_seq"])]
        check(s["hand"] == FOOT and s["drum"] == KICK and s["stick_tip"] == FELT
              and s["bounce"] == 0,
              "its strike %d: hand %d, drum %d, tip %d" % (s["seq"], s["hand"], s["drum"],
                                                         s["stick_tip"]))
        errors.append(float(n["error_ms"]))
    print("kick timing errors, ms: %s" % ["%.3f" % e for e in errors])
    check(max(abs(e) for e in errors) <= 0.5,
          "every kick within 0.5 ms of its time: worst %.3f ms" % max(abs(e) for e in errors))
    foot_primary = [s for s in strikes if s["hand"] == FOOT and s["bounce"] == 0]
    check(len(foot_primary) == len(kicks), "no other primary strike of the foot: %d strikes, %d "
          "kicks" % (len(foot_primary), len(kicks)))
    check(all(s["drum"] == KICK for s in strikes if s["hand"] == FOOT),
          "the foot strikes the kick only")
    check(all(s["hand"] == FOOT for s in strikes if s["drum"] == KICK),
          "no hand strikes the kick")
    times = [s["time_s"] for s in strikes]
    check(all(b >= a for a, b in zip(times, times[1:])),
          "strikes.csv in onset order (seq order is time order)")
    events = e2e_util.read_events(os.path.join(out, "events.txt"))
    check(all(d >= 0 for d, _ in events), "events.txt: no negative delay")
    # The speed law: a louder kick is never slower (velocities of the file, strikes by time).
    speed_of = sorted(zip((t for t, _ in kicks), (s["normal_velocity_mps"] for s in
                                                   sorted(foot_primary, key=lambda s: s["time_s"]))))
    pairs = list(zip((v for _, v in kicks), (v for _, v in speed_of)))
    worst = [(a, b) for a in pairs for b in pairs if a[0] > b[0] and a[1] < b[1] - 1e-6]
    print("kick velocity -> speed, m/s: %s" % sorted(set((v, round(s, 3)) for v, s in pairs)))
    check(not worst, "a louder kick is never slower: %s" % worst[:3])
    mid = mido.MidiFile(os.path.join(out, "performance.mid"))
    kicks_out = sum(1 for m in mid if m.type == "note_on" and m.velocity > 0 and m.note == 36)
    check(kicks_out == len([s for s in strikes if s["hand"] == FOOT]),
          "performance.mid: a note 36 per kick strike: %d" % kicks_out)
    missed = [n for n in hands if n["strike_seq"] == "-1"]
    herr = [abs(float(n["error_ms"])) for n in hands if n["strike_seq"] != "-1"]
    print("hands: %d notes, %d missed, worst timing error %.2f ms"
          % (len(hands), len(missed), max(herr) if herr else float("nan")))

    if not args.no_scores:
        # The example of the full kit: every note struck, the kicks on time.
        example = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "examples",
                               "scores", "groove.txt")
        out_ex = os.path.join(args.workdir, "example")
        env = e2e_util.pd_spawning_env(os.path.abspath(args.workdir))
        run = subprocess.run([args.ictusd, "render", "--kit", "full", "--score", example, "--out",
                              out_ex, "--force"], capture_output=True, text=True, timeout=600, env=env)
        check(run.returncode == 0, "examples/scores/groove.txt renders: %s" % run.stderr[-500:])
        with open(os.path.join(out_ex, "notes.csv")) as f:
            ex = list(csv.DictReader(f))
        check(all(n["strike_seq"] != "-1" for n in ex), "examples/scores/groove.txt: all %d notes "
              "struck" % len(ex))
        check(all(abs(float(n["error_ms"])) <= 0.5 for n in ex if n["hand"] == "right-foot"),
              "examples/scores/groove.txt: its kicks within 0.5 ms")

        # The sticks' runaway guard never holds a kick back: a score (from the random kit scores)
        # whose left stick once flew off the crash's edge after three bounces and fired the guard;
        # every kick is struck either way, and a guard that fired is said. It now plays every
        # note of the hands within 5 ms, the tips never near the guard's 40 m/s (docs/kit.md,
        # "Not done"), so the guard firing beside the kicks is no longer exercised here (the
        # guard's own test: tests/perform/test_live.cpp).
        runaway = os.path.join(args.workdir, "runaway.txt")
        with open(runaway, "w") as f:
            f.write("tempo 214\nr on tom2 legato\nrest 3/4, L 2/2 on tom2 staccato, tempo -> 95 over 1\n"
                    "RF pp + L tenuto on tom2 1/16\nrest 2/1, l accent f 6/32 on crash\nrest 7/8\n"
                    "L on hihat + right accent + rf ff beats 1/32\nrest 3/2\nL f on tom2, rest 1/2\n"
                    "L staccato 0.79 on crash beats 1/3\n"
                    "rest 3/2, left 1/1 accent pp on snare + right-foot f\n")
        out_r = os.path.join(args.workdir, "runaway")
        run = subprocess.run([args.ictusd, "render", "--kit", "full", "--score", runaway, "--out",
                              out_r, "--force"], capture_output=True, text=True, timeout=600, env=env)
        check(run.returncode == 0, "the runaway score renders: %s" % run.stderr[-500:])
        with open(os.path.join(out_r, "notes.csv")) as f:
            kicks_r = [n for n in csv.DictReader(f) if n["hand"] == "right-foot"]
        with open(os.path.join(out_r, "render.json")) as f:
            perf_r = json.load(f)["performance"]
        print("runaway score: guard fired %d time(s), %d strikes held back; kicks %s"
              % (perf_r["runaways"], perf_r["withheld_strikes"], [n["error_ms"] for n in kicks_r]))
        check(len(kicks_r) == 3 and all(n["strike_seq"] != "-1" and abs(float(n["error_ms"])) <= 0.5
                                        for n in kicks_r),
              "every kick of the runaway score struck within 0.5 ms: %s"
              % [(n["time_s"], n["strike_seq"], n["error_ms"]) for n in kicks_r])
        check((perf_r["runaways"] > 0) == ("runaway guard fired" in run.stderr),
              "a guard that fired is said on stderr (and only then): %s" % run.stderr[-300:])
        with open(os.path.join(out_r, "notes.csv")) as f:
            hands_r = [n for n in csv.DictReader(f) if n["hand"] in ("left", "right")]
        check(len(hands_r) == 9 and all(n["strike_seq"] != "-1" and abs(float(n["error_ms"])) <= 5.0
                                        for n in hands_r),
              "every hand's note of the runaway score struck within 5 ms: %s"
              % [(n["time_s"], n["strike_seq"], n["error_ms"]) for n in hands_r])
        check(perf_r["runaways"] == 0, "its left stick stays under the guard's 40 m/s: %d runaway(s)"
              % perf_r["runaways"])

    # 2. Kicks alone, pp to ff (seeded order): the kick's fundamental.
    dyn = ["pp", "p", "mp", "mf", "f", "ff"]
    rng.shuffle(dyn)
    score = os.path.join(args.workdir, "kicks.txt")
    with open(score, "w") as f:
        f.write("tempo 60\n" + "\n".join("RF %s" % d for d in dyn) + "\n")
    out, wav = e2e_util.render_kit(args.ictusd, args.workdir, "kicks", "full",
                                   ["--score", score])
    with open(os.path.join(out, "render.json")) as f:
        head = json.load(f)["kit"]["drums"][KICK]
    # The head's (0,1) mode: the kick preset's density (docs/sound.md, its table).
    want = f01(head["radius_m"], head["tension_n_per_m"], 0.345)
    rate, x = e2e_util.read_wav_mono(wav)
    strikes = [s for s in e2e_util.read_strikes(os.path.join(out, "strikes.csv"))
               if s["bounce"] == 0]
    check(len(strikes) == len(dyn), "every kick struck: %d of %d" % (len(strikes), len(dyn)))
    found = sorted((s["normal_velocity_mps"], lowest_peak_hz(x, rate, int(round(s["time_s"] * rate))))
                   for s in strikes)
    print("kicks: speed m/s -> fundamental Hz: %s (the head's (0,1): %.2f Hz)"
          % (["%.2f: %.1f" % p for p in found], want))
    check(all(f0 < 100.0 for _, f0 in found), "every kick's fundamental below 100 Hz")
    # The softest is the linear head's (0,1) (the 60 ms window resolves it to about 3 %); the
    # tension modulation only raises it with the strike (docs/sound.md): never lower as the
    # kicks get faster (1 %: the window's peak estimate).
    check(abs(found[0][1] / want - 1.0) <= 0.03,
          "the softest kick's fundamental %.1f Hz is the (0,1) %.1f Hz (3 %%)" % (found[0][1], want))
    check(all(b[1] >= a[1] * 0.99 for a, b in zip(found, found[1:])),
          "the fundamental rises (or holds) with the kick's speed: %s" % found)
    return 0


if __name__ == "__main__":
    sys.exit(main())
