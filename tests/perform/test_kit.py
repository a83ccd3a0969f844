#!/usr/bin/env python3
"""A kit played by the real `ictusd render --kit standard-timpani --wav` (docs/perform.md, "A kit"):
a score on the snare, two toms and the timpani, both hands, moving between drums at 100 and
150 bpm (and two timpani played with felt mallets: the tip in strikes.csv and render.json).
Each written note gets one primary strike of its hand on its written drum within
+-5 ms (notes.csv, whose strike matching requires the drum, and strikes.csv's drum column), no
extra primary strike, no stick part through a shell (render.json's kit.shell_passes), and each
strike sounds from its own drum's membrane~: in the 150 ms after each strike onset, of the
drums' pairs of lowest ringing partials, the one with the most energy (Goertzel, summed over
the pair) is its drum's (a pair, as tom2's (0,1) and the timpani's (1,1) are both 110 Hz). The
partials are the ideal membrane's (0,1) and (1,1), j_mn / (2 pi a) sqrt(T / sigma), from the
preset values written here (docs/sound.md, "Presets"), the toms' with the air's mass on both
faces (ictus_tools.drumtone.mode_hz), and the timpani's air-loaded (1,1) and (2,1) at 110 and
165 Hz.

    PYTHONPATH=python python3 tests/perform/test_kit.py --ictusd build/ictusd
"""
import argparse
import csv
import json
import os
import subprocess
import sys

from ictus_tools import e2e_util
from ictus_tools.checks import check
from ictus_tools.drumtone import f01, goertzel_power, mode_hz

SCORE = """tempo 100
drum snare
R, L, R, L
drum tom1
L, R
R on tom2, L on tom2
drum timpani
L at 0.6 180, L at 0.6 180
R on snare, L on snare
R on tom1, L on tom2, R on snare, L at 0.6 180
tempo 150
L on tom1, R on tom2, L on snare, R on tom2
L on snare, R on snare, L on tom1, R on tom1
"""
# Two timpani, the player between them: each hand on its own drum and crossing over, struck a
# quarter to two fifths in from the rim on the player's side.
TIMPANI = """tempo 90
drum timpani1
L at 0.6 90, R at 0.6 90
drum timpani2
R at 0.6 90, L at 0.6 90
L on timpani1 at 0.6 90, R at 0.6 90 on timpani2
R on timpani2 at 0.6 90, L on timpani1 at 0.6 90
L on timpani1 at 0.5 70, R on timpani2 at 0.5 110
"""
# radius m, tension N/m, density kg/m^2 (externals/core/membrane_presets.c; the 10-inch tom is
# the tom preset's head on a 10-inch shell).
HEADS = {"snare": (0.1778, 3603.0, 0.345), "tom1": (0.127, 1465.7, 0.491, 2.0),
         "tom2": (0.1524, 1465.7, 0.491, 2.0)}
F_TIMPANI = (110.0, 165.0)  # (1,1) and (2,1), air-loaded (Rossing's 1 : 1.50)



def played_right(out, drums):
    """Each note of the render in `out` one primary strike of its hand on its drum within +-5 ms,
    no extra primary, no shell passes; returns the notes, strikes, the kit's drum names, the
    primary strikes and whether all held."""
    with open(os.path.join(out, "notes.csv")) as f:
        notes = list(csv.DictReader(f))
    with open(os.path.join(out, "strikes.csv")) as f:
        strikes = list(csv.DictReader(f))
    with open(os.path.join(out, "render.json")) as f:
        summary = json.load(f)
    names = [d["name"] for d in summary["kit"]["drums"]]
    written = sorted({n["drum"] for n in notes})
    ok = check(written == drums, "the score plays %s: %s" % (", ".join(drums), written))
    by_seq = {int(s["seq"]): s for s in strikes}
    worst = 0.0
    for n in notes:
        seq = int(n["strike_seq"]) if n["strike_seq"] else -1
        if not check(seq >= 0, "note %s (line %s, %s) struck" % (n["index"], n["line"], n["drum"])):
            ok = False
            continue
        s = by_seq[seq]
        ok &= check(names[int(s["drum"])] == n["drum"] and int(s["hand"]) == (n["hand"] == "right"),
                    "note %s: its strike is on %s by its hand" % (n["index"], n["drum"]))
        worst = max(worst, abs(float(n["error_ms"])))
    primaries = [s for s in strikes if s["bounce"] == "0"]
    ok &= check(len(primaries) == len(notes),
                "one primary strike per note: %d strikes, %d notes" % (len(primaries), len(notes)))
    ok &= check(worst <= 5.0, "every note within +-5 ms: worst %.2f ms" % worst)
    ok &= check(summary["kit"]["shell_passes"] == 0,
                "no stick part through a shell: %d" % summary["kit"]["shell_passes"])
    return notes, strikes, names, primaries, ok


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ictusd", required=True)
    ap.add_argument("--workdir", default="kit-test")
    args = ap.parse_args()
    os.makedirs(args.workdir, exist_ok=True)
    score = os.path.join(args.workdir, "kit.txt")
    with open(score, "w") as f:
        f.write(SCORE)
    out = os.path.join(args.workdir, "out")
    wav = os.path.join(out, "kit.wav")
    cmd = [args.ictusd, "render", "--kit", "standard-timpani", "--score", score, "--out", out,
           "--force", "--wav", wav]
    # ictusd runs pd itself (under the ASan build through a wrapper that preloads the runtime)
    env = e2e_util.pd_spawning_env(os.path.abspath(args.workdir))
    run = subprocess.run(cmd, capture_output=True, text=True, timeout=600, env=env)
    ok = check(run.returncode == 0, "ictusd render --kit: exit %d %s" % (run.returncode, run.stderr))
    if not ok:
        return 1
    notes, strikes, names, primaries, ok = played_right(out, ["snare", "timpani", "tom1", "tom2"])
    # Each strike's sound: its drum's two lowest ringing partials have the most energy of
    # the drums' pairs (tom2's (0,1) and the timpani's (1,1) are both A2, 110 Hz).
    freq = {k: (f01(*v), mode_hz(*v[:3], 1, 1, *v[3:])) for k, v in HEADS.items()}
    freq["timpani"] = F_TIMPANI
    rate, x = e2e_util.read_wav_mono(wav)
    right = 0
    for s in primaries:
        i0 = int(round(float(s["time_s"]) * rate)) + int(0.005 * rate)
        seg = x[i0:i0 + int(0.15 * rate)]
        power = {k: sum(goertzel_power(seg, rate, f) for f in fs) for k, fs in freq.items()}
        loudest = max(power, key=power.get)
        right += loudest == names[int(s["drum"])]
    ok &= check(right == len(primaries),
                "each strike sounds loudest at its drum's two lowest partials: %d of %d "
                "(partials %s Hz)" % (right, len(primaries),
                                     {k: [round(f, 1) for f in v] for k, v in freq.items()}))
    print("kit: %d notes, %d of %d strikes sound from their drum" % (len(notes), right,
                                                                    len(primaries)))
    # Two timpani (no sound): the hands on their own drums and crossing over.
    score = os.path.join(args.workdir, "timpani.txt")
    with open(score, "w") as f:
        f.write(TIMPANI)
    out = os.path.join(args.workdir, "timpani")
    # pd through a wrapper that writes down its arguments: the drums' messages ictusd gives it
    argv_log = os.path.join(os.path.abspath(args.workdir), "pd-argv.txt")
    wrapper = os.path.join(os.path.abspath(args.workdir), "pd-logging")
    with open(wrapper, "w") as f:
        f.write('#!/bin/sh\nprintf "%%s\\n" "$@" > %s\nexec pd "$@"\n' % argv_log)
    os.chmod(wrapper, 0o755)
    run = subprocess.run([args.ictusd, "render", "--kit", "timpani", "--score", score, "--out",
                          out, "--force", "--stick-tip", "felt", "--wav",
                          os.path.join(out, "timpani.wav"), "--pd", wrapper],
                         capture_output=True, text=True, timeout=600, env=env)
    ok &= check(run.returncode == 0, "ictusd render --kit timpani --stick-tip felt: exit %d %s"
                % (run.returncode, run.stderr))
    _, strikes, _, _, played = played_right(out, ["timpani1", "timpani2"])
    ok &= played
    # The sticks' tip in the record (docs/osc.md): felt is code 3 (stick_tip.h's order + 1), on
    # every strike and every kit drum of render.json.
    with open(os.path.join(out, "render.json")) as f:
        summary = json.load(f)
    ok &= check(all(s["stick_tip"] == "3" for s in strikes), "every strike's stick_tip is 3 (felt)")
    ok &= check(summary["drum"]["stick_tip"] == "felt" and summary["drum"]["stick_tip_code"] == 3
                and all(d["stick_tip"] == "felt" for d in summary["kit"]["drums"]),
                "render.json: the drum's and each kit drum's stick tip is felt")
    with open(argv_log) as f:
        sends = f.read().split("\n")
    want = ["render-drum left tip felt", "render-drum right tip felt",
            "render-kit-1 left tip felt", "render-kit-1 right tip felt"]
    ok &= check(all(w in sends for w in want), "the render gives every drum's sticks the tip: %s"
                % [l for l in sends if " tip " in l])
    # The installed example (no sound): a groove and a fill on the standard kit.
    example = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "examples",
                           "scores", "kit.txt")
    out = os.path.join(args.workdir, "example")
    run = subprocess.run([args.ictusd, "render", "--kit", "standard", "--score", example, "--out",
                          out, "--force"], capture_output=True, text=True, timeout=600)
    ok &= check(run.returncode == 0, "ictusd render --kit standard examples/scores/kit.txt: "
                "exit %d %s" % (run.returncode, run.stderr))
    ok &= played_right(out, ["floor", "snare", "tom1", "tom2"])[4]
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
