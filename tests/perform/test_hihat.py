#!/usr/bin/env python3
"""The hi-hat of `--kit standard-cymbals` played by the real `ictusd render --wav` (docs/kit.md,
"The hi-hat"): a score of closed and open hi-hat notes (docs/score.md, `open`, `closed`), each
note's pedal carried from the score through the planner and its strike to the sound.

Checked: every hi-hat note struck once on the hi-hat, and no other strike (the hand's way
back to rest passes over the plate); events.txt has a `pedal 6 <openness>` line
right before (0 ms) the hit that plays a note whose pedal differs from the last one written, and
no other pedal line; pd.log has no error line; and in the WAV each open note rings longer than
each closed one: the energy of 20 ms windows from 100 to 400 ms after each onset, in dB, fitted
by a line, gives a decay time T60 = -60 dB / slope; the physics of the plate (docs/plates.md,
"The hi-hat": closed T60 0.23 s, open 2.5 s) bounds it: closed < 0.3 s, open > 1 s.

    PYTHONPATH=python python3 tests/perform/test_hihat.py --ictusd build/ictusd
"""
import argparse
import csv
import json
import os
import subprocess
import sys

from ictus_tools import e2e_util
from ictus_tools.checks import check
from ictus_tools.drumtone import decay_t60

# Two seconds between notes (60 bpm, 2 beats): an open note rings on to the window's end.
SCORE = """tempo 60
drum hihat
L closed 2/1, L open 2/1, L closed 2/1, L open 2/1, L 2/1
"""
WANT = [0.0, 1.0, 0.0, 1.0, 0.0]  # the notes' pedals (none written: closed)
HIHAT = 6  # its index in standard-cymbals


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ictusd", required=True)
    ap.add_argument("--workdir", default="hihat-test")
    args = ap.parse_args()
    os.makedirs(args.workdir, exist_ok=True)
    score = os.path.join(args.workdir, "hihat.txt")
    with open(score, "w") as f:
        f.write(SCORE)
    out = os.path.join(args.workdir, "out")
    wav = os.path.join(out, "hihat.wav")
    env = e2e_util.pd_spawning_env(os.path.abspath(args.workdir))
    run = subprocess.run([args.ictusd, "render", "--kit", "standard-cymbals", "--score", score,
                          "--out", out, "--force", "--wav", wav],
                         capture_output=True, text=True, timeout=600, env=env)
    if not check(run.returncode == 0, "ictusd render --kit standard-cymbals --wav: exit %d %s"
                 % (run.returncode, run.stderr)):
        return 1
    with open(os.path.join(out, "render.json")) as f:
        names = [d["name"] for d in json.load(f)["kit"]["drums"]]
    ok = check(names.index("hihat") == HIHAT, "the hi-hat is drum %d: %s" % (HIHAT, names))
    with open(os.path.join(out, "notes.csv")) as f:
        notes = list(csv.DictReader(f))
    strikes = {s["seq"]: s for s in e2e_util.read_strikes(os.path.join(out, "strikes.csv"))}
    ok &= check(len(notes) == len(WANT) and all(n["drum"] == "hihat" and n["strike_seq"] != "-1"
                                                for n in notes),
                "every hi-hat note struck: %s" % [(n["drum"], n["strike_seq"]) for n in notes])
    if not ok:
        return 1
    # No other strike: the hand's way back to rest passes over the plate (docs/kit.md).
    with open(os.path.join(out, "render.json")) as f:
        extra = json.load(f)["performance"]["extra_strikes"]
    primaries = [s for s in strikes.values() if s["bounce"] == 0]
    ok &= check(extra == 0 and len(primaries) == len(notes),
                "one primary strike per note, none extra: %d strikes, %d notes, %d extra"
                % (len(primaries), len(notes), extra))
    onsets = [strikes[int(n["strike_seq"])]["time_s"] for n in notes]
    print("hihat: timing errors %s ms" % [n["error_ms"] for n in notes])
    # events.txt: a pedal line right before each hit whose pedal changed, and no other.
    events = e2e_util.read_events(os.path.join(out, "events.txt"))
    t, last, pedal_at = 0, None, {}
    for i, (delay_us, words) in enumerate(events):
        t += delay_us
        if words[0] == "pedal":
            nxt = events[i + 1] if i + 1 < len(events) else (None, ["none"])
            ok &= check(words[1] == str(HIHAT) and nxt[1][0] == "hit" and nxt[0] == 0
                        and nxt[1][2] == str(HIHAT),
                        "pedal line %d: on the hi-hat, 0 ms before a hit on it: %s / %s"
                        % (i + 1, words, nxt))
            pedal_at[t] = float(words[2])
    want_pedals, prev = {}, None
    for onset, p in zip(onsets, WANT):
        if p != prev:
            want_pedals[round(onset * 1e6)] = p
        prev = p
    ok &= check(pedal_at == want_pedals, "the pedal lines (time us: openness) %s, want %s"
                % (sorted(pedal_at.items()), sorted(want_pedals.items())))
    with open(os.path.join(out, "pd.log")) as f:
        errors = [l for l in f if "error" in l.lower()]
    ok &= check(not errors, "pd.log has no error line: %s" % errors[:3])
    rate, x = e2e_util.read_wav_mono(wav)
    t60 = [decay_t60(x, rate, s) for s in onsets]
    closed = [t for t, p in zip(t60, WANT) if p == 0.0]
    opened = [t for t, p in zip(t60, WANT) if p == 1.0]
    print("hihat: T60 100-400 ms after the onset: closed %s s, open %s s"
          % (["%.3f" % t for t in closed], ["%.3f" % t for t in opened]))
    ok &= check(max(closed) < 0.3, "closed notes' T60 < 0.3 s: %s" % closed)
    ok &= check(min(opened) > 1.0, "open notes' T60 > 1 s: %s" % opened)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
