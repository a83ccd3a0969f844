#!/usr/bin/env python3
"""The hi-hat's chick of `--kit full`: the left foot closing the hi-hat's pedal (docs/pedal.md,
"The hi-hat's pedal"), through the real `ictusd render --wav` and the real pd:

1. A drum part written here as a Standard MIDI File (mido, an independent writer): seeded
   random bars at a seeded random tempo of 8th-note hi-hat by the right hand (42, an open 46
   on some "and"s), the snare (38) on 2 and 4, kicks (36) on 1 and seeded 8ths, and pedal
   hi-hats (44, the chick) on seeded quarter notes at seeded velocities, read by `--midi`.
   Every chick is one primary strike of the left foot (strikes.csv hand 3) on the hi-hat
   (drum 6) within 5 ms of its time, no other strike of that foot; the last pedal line on the
   hi-hat before each chick's hit in events.txt is closed (0); strikes.csv is in onset order;
   a louder chick closes faster; performance.mid has a note 44 per chick strike; render.json
   counts the left foot's notes; pd.log has no error line.
2. A score of chicks alone (`LF` pp .. ff, seeded order, 1 s apart) and mf notes of the left
   hand on the closed hi-hat: each chick's onset is in the sound (the 10 ms after it at
   least 20 dB above the 10 ms before), it decays fast (T60 < 0.3 s, 100..400 ms after it,
   the closed hat's bound in test_hihat.py), and its level (the first 50 ms, RMS) is below
   every mf hand note's.

    PYTHONPATH=python python3 tests/perform/test_chick.py --ictusd build/ictusd
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
from ictus_tools.drumtone import decay_t60, level_db

mido = e2e_util.require_mido()

HIHAT = 6  # its index in `full`
LEFT_FOOT = 3  # strikes.csv's hand of the left foot
BOTH_FEET_BEATS = 36  # kicks with chicks: which foot lands first (by us) varies with the speeds


def groove(path, rng):
    """4 bars in 4/4 (tpq 480): 8th hi-hats (some open), snare 2 and 4, kicks, random chicks."""
    tpq = 480
    bpm = rng.uniform(90.0, 130.0)
    events = []  # (tick, note, velocity)
    chicks = []
    for bar in range(4):
        for eighth in range(8):
            tick = (bar * 8 + eighth) * tpq // 2
            open_hat = eighth % 2 == 1 and rng.random() < 0.25
            events.append((tick, 46 if open_hat else 42, rng.randint(60, 100)))
            if eighth in (2, 6):
                events.append((tick, 38, rng.randint(80, 110)))
            if eighth == 0 or (eighth != 4 and rng.random() < 0.25):
                events.append((tick, 36, rng.randint(60, 120)))
            if eighth % 2 == 0 and (eighth in (2, 6) or rng.random() < 0.4):
                v = rng.randint(20, 127)
                events.append((tick, 44, v))
                chicks.append((tick, v))
    e2e_util.write_drum_midi(mido, path, events, bpm, tpq)
    return bpm, chicks


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ictusd", required=True)
    ap.add_argument("--workdir", default="chick-test")
    ap.add_argument("--seed", type=int, default=44)
    ap.add_argument("--both-feet-beats", type=int, default=BOTH_FEET_BEATS,
                    help="seeded chords of both feet (the first K of the %d)" % BOTH_FEET_BEATS)
    args = ap.parse_args()
    os.makedirs(args.workdir, exist_ok=True)
    rng = random.Random(args.seed)
    ok = True

    # 1. The groove from a MIDI file.
    part = os.path.join(args.workdir, "groove.mid")
    bpm, chicks = groove(part, rng)
    print("groove: %.1f bpm, %d chicks" % (bpm, len(chicks)))
    out, _ = e2e_util.render_kit(args.ictusd, args.workdir, "groove", "full",
                                 ["--midi", part])
    with open(os.path.join(out, "render.json")) as f:
        rj = json.load(f)
    ok &= check(rj["kit"]["drums"][HIHAT]["name"] == "hihat", "the hi-hat is drum %d" % HIHAT)
    ok &= check(rj["performance"].get("left_foot_notes") == len(chicks),
                "render.json: %s left-foot notes, %d chicks"
                % (rj["performance"].get("left_foot_notes"), len(chicks)))
    with open(os.path.join(out, "notes.csv")) as f:
        notes = list(csv.DictReader(f))
    feet = [n for n in notes if n["hand"] == "left-foot"]
    ok &= check(len(feet) == len(chicks), "notes.csv: one left-foot note per chick: %d of %d"
                % (len(feet), len(chicks)))
    strikes = e2e_util.read_strikes(os.path.join(out, "strikes.csv"))
    by_seq = {s["seq"]: s for s in strikes}
    errors = []
    for n in feet:
        if not check(n["drum"] == "hihat" and n["strike_seq"] != "-1",
                     "chick at %s s struck on the hi-hat: %s" % (n["time_s"], n["strike_seq"])):
            ok = False
            continue
        s = by_seq[int(n["strike_seq"])]
        ok &= check(s["hand"] == LEFT_FOOT and s["drum"] == HIHAT and s["bounce"] == 0,
                    "its strike %d: hand %d, drum %d" % (s["seq"], s["hand"], s["drum"]))
        errors.append(float(n["error_ms"]))
    worst = max(abs(e) for e in errors) if errors else float("nan")
    print("chick timing errors, ms: %s (worst %.3f)" % (["%.3f" % e for e in errors], worst))
    ok &= check(worst <= 5.0, "every chick within 5 ms of its time: worst %.3f ms" % worst)
    foot = [s for s in strikes if s["hand"] == LEFT_FOOT]
    primary = [s for s in foot if s["bounce"] == 0]
    ok &= check(len(primary) == len(chicks) and all(s["drum"] == HIHAT for s in foot),
                "the left foot's strikes: %d primary (%d chicks), all on the hi-hat"
                % (len(primary), len(chicks)))
    times = [s["time_s"] for s in strikes]
    ok &= check(all(b >= a for a, b in zip(times, times[1:])), "strikes.csv in onset order")
    # events.txt: the hi-hat's pedal is closed when each chick plays (a pedal line 0 before it
    # if an open note came between).
    events = e2e_util.read_events(os.path.join(out, "events.txt"))
    pedal, closed_at_chick, opened = None, [], 0
    for delay, words in events:
        if words[0] == "pedal" and words[1] == str(HIHAT):
            pedal = float(words[2])
            opened += pedal > 0.0
        elif words[0] == "hit" and words[1] == str(LEFT_FOOT):
            closed_at_chick.append(pedal)
    ok &= check(opened > 0 and all(p == 0.0 for p in closed_at_chick),
                "events.txt: the pedal opened %d times, closed at every chick: %s"
                % (opened, closed_at_chick))
    # The speed law: a louder chick is never slower.
    speeds = [s["normal_velocity_mps"] for s in sorted(primary, key=lambda s: s["time_s"])]
    pairs = list(zip((v for _, v in sorted(chicks)), speeds))
    bad = [(a, b) for a in pairs for b in pairs if a[0] > b[0] and a[1] < b[1] - 1e-6]
    print("chick velocity -> speed, m/s: %s" % sorted(set((v, round(s, 3)) for v, s in pairs)))
    ok &= check(not bad, "a louder chick is never slower: %s" % bad[:3])
    mid = mido.MidiFile(os.path.join(out, "performance.mid"))
    out44 = sum(1 for m in mid if m.type == "note_on" and m.velocity > 0 and m.note == 44)
    ok &= check(out44 == len(foot), "performance.mid: a note 44 per chick strike: %d of %d"
                % (out44, len(foot)))
    hands = [n for n in notes if n["hand"] in ("left", "right")]
    herr = [abs(float(n["error_ms"])) for n in hands if n["strike_seq"] != "-1"]
    print("hands: %d notes, %d missed, worst timing error %.2f ms"
          % (len(hands), sum(n["strike_seq"] == "-1" for n in hands),
             max(herr) if herr else float("nan")))

    # 2. Chicks alone, pp to ff (seeded order), then mf notes of the left hand on the hat.
    dyn = ["pp", "p", "mp", "mf", "f", "ff"]
    rng.shuffle(dyn)
    score = os.path.join(args.workdir, "chicks.txt")
    with open(score, "w") as f:
        f.write("tempo 60\n" + "\n".join("LF %s" % d for d in dyn) +
                "\nL on hihat mf\nL on hihat mf\nL on hihat mf\n")
    out, wav = e2e_util.render_kit(args.ictusd, args.workdir, "chicks", "full",
                                   ["--score", score])
    rate, x = e2e_util.read_wav_mono(wav)
    strikes = [s for s in e2e_util.read_strikes(os.path.join(out, "strikes.csv"))
               if s["bounce"] == 0]
    ch = [s for s in strikes if s["hand"] == LEFT_FOOT]
    hand = [s for s in strikes if s["hand"] == 0 and s["drum"] == HIHAT]
    ok &= check(len(ch) == len(dyn) and len(hand) == 3,
                "every chick and hand note struck: %d chicks, %d hand" % (len(ch), len(hand)))
    rows = []
    for s in ch + hand:
        t = s["time_s"]
        rise = level_db(x, rate, t, t + 0.010) - level_db(x, rate, t - 0.010, t)
        rows.append((s["hand"], s["normal_velocity_mps"], rise, decay_t60(x, rate, t),
                     level_db(x, rate, t, t + 0.050)))
    for r in rows:
        print("%s %.2f m/s: onset +%.1f dB, T60 %.3f s, level %.1f dB"
              % ("chick" if r[0] == LEFT_FOOT else "hand mf", r[1], r[2], r[3], r[4]))
    chick_rows = [r for r in rows if r[0] == LEFT_FOOT]
    hand_rows = [r for r in rows if r[0] != LEFT_FOOT]
    ok &= check(all(r[2] >= 20.0 for r in chick_rows), "every chick's onset in the sound "
                "(>= 20 dB over the 10 ms before)")
    ok &= check(all(r[3] < 0.3 for r in chick_rows), "every chick's T60 < 0.3 s")
    ok &= check(hand_rows and max(r[4] for r in chick_rows) < min(r[4] for r in hand_rows),
                "every chick below every mf hand note: %.1f dB < %.1f dB"
                % (max(r[4] for r in chick_rows), min(r[4] for r in hand_rows) if hand_rows
                   else float("nan")))
    # Both feet on one beat (the kick and the chick together, as a groove's 1 often has): their
    # contacts begin in one physics step, a few us apart; strikes.csv keeps onset order. Seeded
    # chords of the two feet, and a random kit score (seed 160) whose last chord's chick began
    # 1 us before its kick in one step: the feet take their seqs in onset order.
    rng = random.Random(args.seed + 1)
    dyn = ("pp", "p", "mp", "mf", "f", "ff")
    chords = "tempo %d\n" % rng.randint(80, 160) + "".join(
        "RF %s + LF %s %s\n" % (rng.choice(dyn), rng.choice(dyn), rng.choice(("1/2", "1/4", "1/1")))
        for _ in range(BOTH_FEET_BEATS))
    # the first --both-feet-beats chords (the seeded ones, whatever their number)
    chords = "\n".join(chords.split("\n")[:1 + args.both_feet_beats]) + "\n"
    seed160 = ("tempo 71; grip german; R 1 on floor legato; L on snare vertical_accent at 0.57 "
               "10.2 0\nRF 0.5 on kick + r legato pp on ride\nR+L on snare beats 3/4 staccato\n"
               "lf 0 1/6 + left on snare VERTICAL_ACCENT 1/1 + right staccato half on hihat + "
               "right-foot 0.5 beats 1/8 on kick\nRIGHT-FOOT MF + R TENUTO OPEN ON HIHAT + LF "
               "BEATS 0.5\n")
    for name, text, n_feet in (("both-feet", chords, 2 * args.both_feet_beats),
                               ("seed-160", seed160, 5)):
        path = os.path.join(args.workdir, name + ".txt")
        with open(path, "w") as f:
            f.write(text)
        out_b = os.path.join(args.workdir, name)
        run = subprocess.run([args.ictusd, "render", "--kit", "full", "--score", path, "--out",
                              out_b, "--force"], capture_output=True, text=True, timeout=600)
        ok &= check(run.returncode == 0, "%s renders: %s" % (name, run.stderr[-300:]))
        st = e2e_util.read_strikes(os.path.join(out_b, "strikes.csv"))
        feet = [s for s in st if s["hand"] in (2, LEFT_FOOT) and s["bounce"] == 0]
        times = [s["time_s"] for s in st]
        ok &= check(len(feet) == n_feet and all(b >= a_ for a_, b in zip(times, times[1:])),
                    "%s: %d foot strikes of %d, strikes.csv in onset order"
                    % (name, len(feet), n_feet))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
