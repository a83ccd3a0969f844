#!/usr/bin/env python3
"""A hand that moves to another piece of the kit for its soft strokes comes over its edge and
its head above them (docs/kit.md, "Playing it"): seeded two-note scores on `--kit full`, a note
of one hand on a drum or the ride, then a note of the other hand with a flam or a drag on another
of them (the ride's strokes the right hand's), whose grace strokes
(legato at dynamics 0.15: low) the first hand plays there after its move, at 70..140 bpm;
rendered by the real `ictusd render`. Expected here from the score alone: the note at beat 1
(60 / bpm after beat 0, the plan's origin + lead-in), a flam's grace 30 ms before it, a drag's
70 and 30 ms before. Each note and grace one primary strike of its hand on its drum within
+-5 ms, and no other primary strike. Before the bead's clearance, seeds struck the grace's piece
once more on the way, 0.2-0.5 s early, on a drum's edge (`tempo 87, R on snare, L on tom1 drag`)
or the ride's bow (`tempo 77, R on snare, L on ride flam`).

    PYTHONPATH=python python3 tests/perform/test_grace_moves.py --ictusd build/ictusd --count 12
"""
import argparse
import json
import os
import random
import subprocess

from ictus_tools import e2e_util, render_check
from ictus_tools.checks import check

DRUMS = ["snare", "tom1", "tom2", "floor", "ride"]
GRACE_LEADS_S = {"flam": [0.030], "drag": [0.070, 0.030]}
TOLERANCE_S = 0.005


def score(seed):
    """(text, [(time from beat 0 s, hand 0 left / 1 right, drum)]) of seed."""
    rng = random.Random(seed)
    bpm = rng.randint(70, 140)
    first, second = rng.sample(DRUMS, 2)
    # The ride stands right of the floor tom: the right hand's (the left's strokes there
    # cross the body, beyond what it reaches in time: seeded 3 of 30 late, early or doubled).
    mover = "R" if "ride" in (first, second) else rng.choice(["R", "L"])
    other = "L" if mover == "R" else "R"
    how = rng.choice(["flam", "drag"])
    text = "tempo %d\n%s on %s\n%s on %s %s\nrest\n" % (bpm, mover, first, other, second, how)
    hand = {"L": 0, "R": 1}
    beat_s = 60.0 / bpm
    want = [(0.0, hand[mover], first), (beat_s, hand[other], second)]
    want += [(beat_s - lead, hand[mover], second) for lead in GRACE_LEADS_S[how]]
    return text, sorted(want)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ictusd", required=True)
    ap.add_argument("--first", type=int, default=0)
    ap.add_argument("--count", type=int, default=12)
    ap.add_argument("--workdir", help="where the renders go (emptied first; else a temporary folder)")
    a = ap.parse_args()
    work = render_check.empty_workdir(a.workdir, "ictus-grace-moves-")
    for seed in range(a.first, a.first + a.count):
        text, want = score(seed)
        path = os.path.join(work, "seed%d.txt" % seed)
        with open(path, "w") as f:
            f.write(text)
        out = os.path.join(work, "seed%d" % seed)
        proc = subprocess.run([a.ictusd, "render", "--score", path, "--kit", "full", "--out", out,
                               "--bvh-rate", "0", "--tips-rate", "0"],
                              capture_output=True, text=True, timeout=600)
        where = "seed %d (%s)" % (seed, text.strip().replace("\n", ", "))
        check(proc.returncode == 0, "%s rendered: %s" % (where, proc.stderr[-1000:]))
        with open(os.path.join(out, "render.json")) as f:
            rj = json.load(f)
        names = [d["name"] for d in rj["kit"]["drums"]]
        plan = rj["performance"]["plan"]
        beat0 = plan["origin_s"] + plan["lead_in_s"]
        strikes = [s for s in e2e_util.read_strikes(os.path.join(out, "strikes.csv"))
                   if not s["bounce"]]
        used = set()
        for t, hand, drum in want:
            near = [i for i, s in enumerate(strikes) if i not in used and s["hand"] == hand
                    and names[s["drum"]] == drum
                    and abs(s["time_s"] - beat0 - t) <= TOLERANCE_S]
            check(near, "%s: the %s hand's stroke on %s at %.3f s struck within 5 ms"
                  % (where, "right" if hand else "left", drum, t))
            used.add(min(near, key=lambda i: abs(strikes[i]["time_s"] - beat0 - t)))
        extra = ["%s hand on %s at %.3f s" % ("right" if s["hand"] else "left", names[s["drum"]],
                                              s["time_s"] - beat0)
                 for i, s in enumerate(strikes) if i not in used]
        check(not extra, "%s: no other primary strike (%s)" % (where, "; ".join(extra) or "none"))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
