#!/usr/bin/env python3
"""Seeded rudiment scores: what drummers practise first, at drummers' tempi (docs/perform.md,
"Rudiments").

    python3 -m ictus_tools.rudiments --seed N            # print rudiment score N
    python3 -m ictus_tools.rudiments --seed N --notes    # and the notes it must give

(with python/ on PYTHONPATH). Each score is one rudiment, a constant tempo and a subdivision,
a dynamics and a nuance, repeated a few times: singles (R L R L) in 16ths up to 240 bpm, doubles
(R R L L) and paradiddles (R L R R L R L L) with same-hand strokes MIN_SAME_HAND_S .. 0.1 s apart
(and slower). The notes (times from beat 0, at a constant tempo t = beat * 60 / bpm) are
computed here, not taken from the daemon, so that ictus_tools.render_check can judge a render
of the score against them. The same seed gives the same bytes (random.Random(seed)).
"""
import argparse
import random
from concurrent.futures import ThreadPoolExecutor

MIN_SAME_HAND_S = 0.060       # the shortest same-hand interval the rudiments ask for
PAIR_SPEED_TOL = 0.20         # a double's second impact within 20 % of the first (the acceptance)
DEFAULT_R_OVER_A = 0.3
DEFAULT_THETA = {"right": 180.0, "left": 0.0}
DYNAMICS_WORDS = [("p", 0.3), ("mp", 0.45), ("mf", 0.6), ("f", 0.8)]
NUANCES = ["legato", "staccato"]

# name: sticking of one pass (R/L), and how far apart the closest same-hand strokes are in
# subdivisions (1: doubles, 2: singles).
RUDIMENTS = {
    "singles": ("RLRL", 2),
    "doubles": ("RRLL", 1),
    "paradiddle": ("RLRRLRLL", 1),
}


class RudimentScore:
    """A generated rudiment score: `seed`, `text`, `notes` (time_s from beat 0, hand, nuance, grip,
    dynamics, beats, tempo_bpm, r_over_a, theta_deg, line), `rudiment`, `tempo_bpm`, `sub`
    (the subdivision in beats), `same_hand_s` (the closest same-hand interval)."""

    def __init__(self, seed, rudiment=None, same_hand_s=None):
        rng = random.Random(seed)
        forced_s = same_hand_s
        self.seed = seed
        self.rudiment = rudiment or rng.choice(sorted(RUDIMENTS))
        sticking, closest = RUDIMENTS[self.rudiment]
        if closest == 1:
            # Same-hand strokes one subdivision apart: 60..100 ms (the rebound range), or slower.
            same_hand_s = rng.uniform(MIN_SAME_HAND_S, 0.1) if rng.random() < 0.8 else \
                rng.uniform(0.1, 0.2)
        else:
            same_hand_s = rng.uniform(0.12, 0.25)  # singles: 16ths at 120..250 bpm
        if forced_s is not None:
            same_hand_s = forced_s
        self.sub = rng.choice([0.25, 0.125]) if forced_s is None else 0.125  # 16ths or 32nds
        step_s = same_hand_s / closest
        self.tempo_bpm = round(60.0 * self.sub / step_s, 1)
        step_s = 60.0 * self.sub / self.tempo_bpm  # the tempo as written
        self.same_hand_s = step_s * closest
        word, dyn = rng.choice(DYNAMICS_WORDS) if forced_s is None else ("mf", 0.6)
        nuance = rng.choice(NUANCES)
        passes = rng.randint(2, 4)
        self.physical_grip = "french"
        lines = ["# rudiment %s, seed %d" % (self.rudiment, seed),
                 "tempo %g" % self.tempo_bpm, "beats 1/%d" % round(1 / self.sub),
                 "dynamics %s" % word, "nuance %s" % nuance, "repeat %d" % passes,
                 ", ".join(sticking), "end"]
        self.text = "\n".join(lines) + "\n"
        body_line = 7
        self.notes = []
        for k in range(passes * len(sticking)):
            hand = "right" if sticking[k % len(sticking)] == "R" else "left"
            self.notes.append({
                "time_s": k * step_s, "hand": hand, "nuance": nuance, "grip": "french",
                "dynamics": dyn, "beats": self.sub, "tempo_bpm": self.tempo_bpm,
                "r_over_a": DEFAULT_R_OVER_A, "theta_deg": DEFAULT_THETA[hand],
                "line": body_line})

    def write(self, path):
        with open(path, "w") as f:
            f.write(self.text)


def pair_problems(res):
    """Same-hand pairs one subdivision apart (doubles): the second impact within 20 % of the first."""
    score = res.score
    out = []
    if score.rudiment == "singles":
        return out
    step = 60.0 * score.sub / score.tempo_bpm
    notes = sorted(res.notes, key=lambda n: n["plan_time_s"])
    by_hand = {}
    for n in notes:
        by_hand.setdefault(n["hand"], []).append(n)
    for hand, ns in by_hand.items():
        k = 0
        while k + 1 < len(ns):
            a, b = ns[k], ns[k + 1]
            if abs((b["plan_time_s"] - a["plan_time_s"]) - step) < 1e-4 and a["strike"] and b["strike"]:
                va = a["strike"]["normal_velocity_mps"]
                vb = b["strike"]["normal_velocity_mps"]
                if abs(vb - va) > PAIR_SPEED_TOL * va:
                    out.append("%s double at %.3f s: second impact %.2f m/s, first %.2f m/s"
                               % (hand, a["plan_time_s"], vb, va))
                k += 2
            else:
                k += 1
    return out


def percentile(xs, q):
    xs = sorted(xs)
    if not xs:
        return float("nan")
    i = min(len(xs) - 1, max(0, int(round(q * (len(xs) - 1)))))
    return xs[i]


def play(ictusd, seeds, workdir, jobs, same_hand_s=None):
    """Renders and judges the rudiment scores of `seeds` (ictus_tools.render_check, plus
    pair_problems); with same_hand_s, doubles at mf at that interval. Returns the Results."""
    from ictus_tools import render_check

    def one(seed):
        score = RudimentScore(seed, "doubles" if same_hand_s else None, same_hand_s)
        res = render_check.render(ictusd, score, workdir)
        if not res.problems:
            res.problems.extend(pair_problems(res))
        return res

    with ThreadPoolExecutor(max_workers=jobs) as ex:
        return list(ex.map(one, seeds))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seed", type=int, required=True)
    ap.add_argument("--rudiment", choices=sorted(RUDIMENTS))
    ap.add_argument("--notes", action="store_true")
    a = ap.parse_args()
    s = RudimentScore(a.seed, a.rudiment)
    print(s.text, end="")
    if a.notes:
        for n in s.notes:
            print("# %.6f %s" % (n["time_s"], n["hand"]))


if __name__ == "__main__":
    main()
