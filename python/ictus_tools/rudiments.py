#!/usr/bin/env python3
"""Seeded rudiment scores: what drummers practise first, at drummers' tempi (docs/perform.md,
"Rudiments").

    python3 -m ictus_tools.rudiments --seed N            # print rudiment score N
    python3 -m ictus_tools.rudiments --seed N --notes    # and the notes it must give

(with python/ on PYTHONPATH). Each score is one rudiment, a constant tempo and a subdivision,
a dynamics and a nuance, repeated a few times: singles (R L R L) in 16ths up to 240 bpm, doubles
(R R L L), paradiddles (R L R R L R L L) and `roll double` with same-hand strokes
MIN_SAME_HAND_S .. 0.1 s apart (and slower), alternating flams, flam taps (R flam, R, L flam, L),
alternating drags and `roll buzz` (RUDIMENTS). The notes (times from beat 0, at a constant tempo
t = beat * 60 / bpm, grace strokes FLAM_LEAD_S and DRAG_SPACING_S before, as docs/score.md
defines them) are computed here, not taken from the daemon, so that ictus_tools.render_check
can judge a render of the score against them. The same seed gives the same bytes
(random.Random(seed)).
"""
import argparse
import csv
import os
import random
from concurrent.futures import ThreadPoolExecutor

MIN_SAME_HAND_S = 0.060       # the shortest same-hand interval the rudiments ask for
PAIR_SPEED_TOL = 0.20         # a double's second impact within 20 % of the first (the acceptance)
DEFAULT_R_OVER_A = 0.3
DEFAULT_THETA = {"right": 180.0, "left": 0.0}
DYNAMICS_WORDS = [("p", 0.3), ("mp", 0.45), ("mf", 0.6), ("f", 0.8)]
NUANCES = ["legato", "staccato"]
# Grace strokes (docs/score.md, "Flams, drags and rolls"), written again here: a flam's grace
# FLAM_LEAD_S before its note, a drag's two at FLAM_LEAD_S + DRAG_SPACING_S and FLAM_LEAD_S,
# legato at GRACE_DYNAMICS (or half the note's).
FLAM_LEAD_S = 0.030
DRAG_SPACING_S = 0.040
GRACE_DYNAMICS = 0.15
GRACE_WINDOW_MS = (10.0, 45.0)  # a grace stroke's strike this long before its note's (the acceptance)

# name: (sticking of one pass: R/L, a trailing f/d marks a flam/drag; how far apart the closest
# same-hand written strokes are in subdivisions (1: doubles, 2: singles); the range of that
# interval (s); the subdivisions drawn from; a roll statement's kind or None).
RUDIMENTS = {
    "singles": (["R", "L", "R", "L"], 2, (0.12, 0.25), [0.25, 0.125], None),
    "doubles": (["R", "R", "L", "L"], 1, None, [0.25, 0.125], None),
    "paradiddle": (list("RLRRLRLL"), 1, None, [0.25, 0.125], None),
    # Alternating flams in 8ths (86..200 bpm), flam taps in 16ths (83..150 bpm).
    "flams": (["Rf", "Lf"], 2, (0.30, 0.70), [0.5], None),
    "flam_taps": (["Rf", "R", "Lf", "L"], 1, (0.10, 0.18), [0.25], None),
    # Alternating drags in 8ths (75..150 bpm).
    "drags": (["Rd", "Ld"], 2, (0.40, 0.80), [0.5], None),
    # `roll double`: RRLL on the rebound as the doubles; `roll buzz`: buzz strokes R L in 16ths
    # or triplets, each hand's 0.2..0.5 s apart.
    "double_roll": (list("RRLL"), 1, None, [0.25, 0.125], "double"),
    "buzz_roll": (list("RLRL"), 2, (0.20, 0.50), [0.25, 1.0 / 3.0], "buzz"),
}
PAIRED = ("doubles", "paradiddle", "double_roll")  # the 20 % rule on same-hand pairs


def _subdivision(sub):
    return "1/3" if abs(sub - 1.0 / 3.0) < 1e-9 else "1/%d" % round(1 / sub)


class RudimentScore:
    """A generated rudiment score: `seed`, `text`, `notes` (time_s from beat 0, hand, nuance, grip,
    dynamics, beats, tempo_bpm, r_over_a, theta_deg, line, grace: "flam"/"drag"/None, principal:
    the index in `notes` of a grace's note), `rudiment`, `tempo_bpm`, `sub` (the subdivision in
    beats), `same_hand_s` (the closest same-hand interval of written notes)."""

    def __init__(self, seed, rudiment=None, same_hand_s=None):
        rng = random.Random(seed)
        forced_s = same_hand_s
        self.seed = seed
        self.rudiment = rudiment or rng.choice(sorted(RUDIMENTS))
        sticking, closest, span, subs, roll = RUDIMENTS[self.rudiment]
        if span is None:
            # Same-hand strokes one subdivision apart: 60..100 ms (the rebound range), or slower.
            same_hand_s = rng.uniform(MIN_SAME_HAND_S, 0.1) if rng.random() < 0.8 else \
                rng.uniform(0.1, 0.2)
        else:
            same_hand_s = rng.uniform(*span)
        if forced_s is not None:
            same_hand_s = forced_s
        self.sub = rng.choice(subs) if forced_s is None else 0.125
        step_s = same_hand_s / closest
        self.tempo_bpm = round(60.0 * self.sub / step_s, 1)
        step_s = 60.0 * self.sub / self.tempo_bpm  # the tempo as written
        self.same_hand_s = step_s * closest
        word, dyn = rng.choice(DYNAMICS_WORDS) if forced_s is None else ("mf", 0.6)
        nuance = rng.choice(NUANCES)
        passes = rng.randint(2, 4)
        self.physical_grip = "french"
        lines = ["# rudiment %s, seed %d" % (self.rudiment, seed),
                 "tempo %g" % self.tempo_bpm, "beats %s" % _subdivision(self.sub),
                 "dynamics %s" % word, "nuance %s" % nuance]
        if roll:
            count = passes * len(sticking)
            lines.append("roll %s %s" % (roll, "%d/%d" % (count, round(1 / self.sub))
                                         if self.sub < 1 / 3.5 else "%d/3" % count))
            written = [sticking[k % len(sticking)] for k in range(count)]
        else:
            lines += ["repeat %d" % passes,
                      ", ".join(w[0] + {"f": " flam", "d": " drag"}.get(w[1:], "")
                                for w in sticking), "end"]
            written = [sticking[k % len(sticking)] for k in range(passes * len(sticking))]
        self.text = "\n".join(lines) + "\n"
        body_line = 6 if roll else 7
        notes = []
        for k, w in enumerate(written):
            hand = "right" if w[0] == "R" else "left"
            t = k * step_s
            note = {"time_s": t, "hand": hand, "nuance": "buzz" if roll == "buzz" else nuance,
                    "grip": "french", "dynamics": dyn, "beats": self.sub,
                    "tempo_bpm": self.tempo_bpm, "r_over_a": DEFAULT_R_OVER_A,
                    "theta_deg": DEFAULT_THETA[hand], "line": body_line, "grace": None}
            other = "left" if hand == "right" else "right"
            leads = {"f": [FLAM_LEAD_S], "d": [FLAM_LEAD_S + DRAG_SPACING_S, FLAM_LEAD_S]}
            for lead in leads.get(w[1:], []):
                notes.append({"time_s": t - lead, "hand": other, "nuance": "legato",
                              "grip": "french", "dynamics": min(GRACE_DYNAMICS, 0.5 * dyn),
                              "beats": 0.0, "tempo_bpm": self.tempo_bpm,
                              "r_over_a": DEFAULT_R_OVER_A, "theta_deg": DEFAULT_THETA[other],
                              "line": body_line, "grace": {"f": "flam", "d": "drag"}[w[1:]],
                              "principal": note})
            notes.append(note)
        # In the order notes.csv is read (time, the right hand first at a tie).
        notes.sort(key=lambda n: (n["time_s"], n["hand"] != "right"))
        for n in notes:
            if n["grace"]:
                n["principal"] = notes.index(n["principal"])
        self.notes = notes

    def write(self, path):
        with open(path, "w") as f:
            f.write(self.text)


def pair_problems(res):
    """Same-hand pairs one subdivision apart (doubles): the second impact within 20 % of the first."""
    score = res.score
    out = []
    if score.rudiment not in PAIRED:
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


def grace_problems(res, out_dir):
    """Each grace stroke's strike 10..45 ms before its note's strike (a drag's first grace: before
    the second grace's strike, the stroke it leads into), and notes.csv's `grace` column marking
    exactly the grace strokes. Also returns the grace leads measured (ms)."""
    problems, leads = [], []
    expected = res.score.notes
    with open(os.path.join(out_dir, "notes.csv")) as f:
        rows = sorted(csv.DictReader(f), key=lambda r: (float(r["time_s"]), r["hand"] != "right"))
    for e, r in zip(expected, rows):
        if r.get("grace") != ("1" if e["grace"] else "0"):
            problems.append("notes.csv row %s: grace %r, the score's note %s" % (
                r["index"], r.get("grace"), "a grace stroke" if e["grace"] else "a written note"))
            break
    by_time = {(round(n["time_s"], 9), n["hand"]): n for n in res.notes}
    recs = [by_time.get((round(e["time_s"], 9), e["hand"])) for e in expected]
    for i, e in enumerate(expected):
        if not e["grace"]:
            continue
        # The stroke it leads into: the next grace of a drag, else the note.
        nxt = e["principal"]
        if e["grace"] == "drag" and i + 1 < len(expected) and expected[i + 1]["grace"] == "drag" \
                and expected[i + 1]["principal"] == e["principal"]:
            nxt = i + 1
        g, n = recs[i], recs[nxt]
        if not (g and n and g["strike"] and n["strike"]):
            continue  # render_check already counts a missed note
        lead = (n["strike"]["time_s"] - g["strike"]["time_s"]) * 1000.0
        leads.append(lead)
        if not GRACE_WINDOW_MS[0] <= lead <= GRACE_WINDOW_MS[1]:
            problems.append("%s grace (%s) at %.3f s struck %.1f ms before the stroke it leads into"
                            " (%g..%g ms)" % (e["grace"], e["hand"], g["plan_time_s"], lead,
                                               GRACE_WINDOW_MS[0], GRACE_WINDOW_MS[1]))
    return problems, leads


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
        res.grace_leads_ms = []
        if not res.problems:
            res.problems.extend(pair_problems(res))
            problems, res.grace_leads_ms = grace_problems(
                res, os.path.join(workdir, "seed-%d" % seed, "out"))
            res.problems.extend(problems)
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
