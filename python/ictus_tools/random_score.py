#!/usr/bin/env python3
"""Seeded random scores in the whole score language (docs/score.md), valid ones only.

    python3 -m ictus_tools.random_score --seed N          # print score N
    python3 -m ictus_tools.random_score --seed N --notes  # and the notes it must give
    python3 -m ictus_tools.random_score --seed N --ictusd build/ictusd   # nuances from that parser
    python3 -m ictus_tools.random_score --coverage 100    # how many of seeds 1..100 hold each form
    python3 -m ictus_tools.random_score --seed N --kit full   # over the kit full (its drums,
                                                   # chords, kicks, cymbals: random_kit_score)

(with python/ on PYTHONPATH, as everywhere for this package: docs/python.md).

Used by tests/perform/test_random_scores.py and test_random_kit_scores.py (CTest) and
bench/random_scores.py. The same seed
and the same nuance list give the same bytes (Python's own `random.Random(seed)`, no hashing
of sets, no clock).

What a score may hold (daemon/src/score/score.cpp is the grammar): statements `R`/`L`/`right`/
`left` [options], `R+L`/`L+R`/`both` [options without `at`, `flam`, `drag`], `tempo BPM`,
`tempo BPM -> BPM2 over BEATS`, `tempo -> BPM2 over BEATS` (`to` for `->`), `grip
french|german`, `rest [[beats] BEATS]`, `beats BEATS`, `dynamics D`, `firmness F`, `meter N/D`,
`roll single|double|buzz BEATS`, `repeat N` ... `end` (nesting); separated by newlines, `;` or
`,`; `#` comments; words in any case. Note options, in any order, each at most once: a nuance,
dynamics (a number 0..1 or pp p mp mf f ff), a duration (N/D or `beats X`), `at R/A THETA`,
`firmness F`, `flam` or `drag` (the other hand's grace strokes, 30 ms, or 70 and 30 ms, before
the note: that hand kept free as for its own notes). Not drawn: `humanize` (its timing noise
moves the strokes off the beats render_check holds them to), hairpins, the `nuance` default.
Here: tempi 40..220 bpm (the brief; the language allows 20..400), durations from the musical
fractions below (whole notes to 1/32, triplets, dotted values, non-reduced forms).

Validity. The parser's ranges are kept by construction. The planner (gesture_score.cpp,
`plan_performance`) also refuses a stroke that comes less than `min_stroke_interval_s` = 40 ms
after the previous stroke of the same hand, and plans over 900 s; here a hand's strokes are kept
at least 0.1 s apart (closer ones, doubles and paradiddles, are ictus_tools.rudiments'). The generator follows the
tempo map itself (the closed-form integral of docs/score.md, written here again, not taken from
the daemon) and keeps every hand's strokes >= MIN_STROKE_INTERVAL_S + 1 us apart: a note whose
hand would come too soon goes to the other hand, and if neither hand can play it a rest comes
first (a repeat whose later passes would break the rule gets a rest at the end of its body, or
is played once). Scores are short (4..14 written notes after repeats and their grace strokes, at
most SCORE_BUDGET_S of score),
so the 900 s limit is never near. The callers count any score `ictusd render` refuses: a refusal
means this model of the rule is wrong, and is reported as a failure.

Nuances: the list is read from the parser -- `ictusd render` on a one-line score with an unknown
nuance prints "unknown nuance '...' (valid: legato, tenuto, ...)" -- when an ictusd is given,
else from kNuanceNames in daemon/src/gesture/gesture_unit.cpp (the names the parser accepts),
else FALLBACK_NUANCES. A new nuance (such as the `buzz`/press stroke) is thus drawn without
touching this file. Other note options: NOTE_OPTIONS below is the one place to add one (e.g. a
grip firmness) -- a name, a drawing function, and whether `R+L` may carry it. The grip
firmness, flams, drags, rolls and meters are drawn from a stream of their own (Generator.extended),
so that a seed's other statements are mostly those drawn without them.
"""
import argparse
import math
import os
import random
import re
import subprocess
import sys
import tempfile

from ictus_tools import ROOT

MIN_STROKE_INTERVAL_S = 0.1   # >= PlanOptions::min_stroke_interval_s (docs/score.md, "Errors")
INTERVAL_MARGIN_S = 1e-6      # our tempo map and the daemon's differ by ~1e-15 s
TEMPO_RANGE = (40.0, 220.0)   # the brief's range (the language's: 20..400)
SCORE_BUDGET_S = 6.0          # at most this much score (beat 0 to the end of the last note)
NOTES_RANGE = (4, 14)         # notes after repeats (R+L counts as two)
LEAD_IN_S = 1.0               # PlanOptions::lead_in_s: beat 0 is at 1 s of the plan
# Grace strokes (docs/score.md, "Flams, drags and rolls"), written again here: a flam's grace
# FLAM_LEAD_S before its note, a drag's two FLAM_LEAD_S + DRAG_SPACING_S and FLAM_LEAD_S before,
# legato at GRACE_DYNAMICS (or half the note's), the other hand's.
FLAM_LEAD_S = 0.030
DRAG_SPACING_S = 0.040
GRACE_DYNAMICS = 0.15
FIRMNESS_VALUES = [0.0, 0.1, 0.2, 0.25, 0.35, 0.5, 0.8, 1.0]
METERS = [(4, 4), (3, 4), (2, 4), (6, 8), (7, 8), (5, 4), (2, 2), (12, 8), (1, 4)]
ROLLS = ["single", "double", "buzz"]

FALLBACK_NUANCES = ["legato", "tenuto", "accent", "vertical_accent", "staccato"]
GRIPS = ["french", "german"]
DYNAMICS_WORDS = [("pp", 0.2), ("p", 0.3), ("mp", 0.45), ("mf", 0.6), ("f", 0.8), ("ff", 1.0)]
DEFAULT_DYNAMICS = 0.6
DEFAULT_THETA = {"right": 180.0, "left": 0.0}
DEFAULT_R_OVER_A = 0.3

# Durations in beats: (numerator, denominator, weight, label). Straight values, triplets
# (1/3, 2/3, 1/6, 1/12), dotted values (3/2, 3/4, 3/8, 3/16), a double-dotted 7/8, long notes.
FRACTIONS = [
    (1, 1, 10, "1"), (1, 2, 10, "1/2"), (1, 4, 8, "1/4"), (1, 8, 5, "1/8"), (1, 16, 3, "1/16"),
    (1, 32, 1, "1/32"), (1, 3, 6, "1/3"), (2, 3, 5, "2/3"), (1, 6, 4, "1/6"), (1, 12, 2, "1/12"),
    (3, 2, 4, "3/2"), (3, 4, 5, "3/4"), (3, 8, 4, "3/8"), (3, 16, 2, "3/16"), (7, 8, 1, "7/8"),
    (2, 1, 3, "2"), (3, 1, 1, "3"), (4, 1, 1, "4"),
]


def nuances_from_parser(ictusd):
    """The nuance names the parser accepts, from its error message for an unknown one."""
    with tempfile.TemporaryDirectory(prefix="ictus-nuances-") as tmp:
        score = os.path.join(tmp, "probe.txt")
        with open(score, "w") as f:
            f.write("R zzznotanuance\n")
        proc = subprocess.run([ictusd, "render", "--score", score, "--out", os.path.join(tmp, "out")],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=60)
    m = re.search(r"unknown nuance 'zzznotanuance' \(valid: ([^)]*)\)", proc.stdout + proc.stderr)
    if not m:
        raise RuntimeError("%s did not name the valid nuances (exit %d): %s"
                           % (ictusd, proc.returncode, (proc.stdout + proc.stderr).strip()))
    return [w.strip() for w in m.group(1).split(",") if w.strip()]


def nuances_from_source(root=ROOT):
    path = os.path.join(root, "daemon", "src", "gesture", "gesture_unit.cpp")
    try:
        with open(path) as f:
            text = f.read()
    except OSError:
        return None
    m = re.search(r"kNuanceNames\[[^\]]*\]\s*=\s*\{([^}]*)\}", text)
    if not m:
        return None
    names = re.findall(r'"([^"]+)"', m.group(1))
    return names or None


def nuance_list(ictusd=None):
    if ictusd:
        return nuances_from_parser(ictusd)
    return nuances_from_source() or list(FALLBACK_NUANCES)


# ------------------------------------------------------------------ tempo map (our own)

class TempoMap:
    """t(b) = integral of 60 / tempo(beta) d beta, tempo linear in beats during a ramp
    (docs/score.md, "Tempo map"). Changes: (beat, start_bpm, end_bpm, ramp_beats, start_time)."""

    def __init__(self, bpm=120.0):
        self.changes = [[0.0, bpm, bpm, 0.0, 0.0]]

    def copy(self):
        t = TempoMap()
        t.changes = [list(c) for c in self.changes]
        return t

    @staticmethod
    def _ramp_time(t0, t1, ramp, beats):
        if beats <= 0.0:
            return 0.0
        if ramp <= 0.0 or t1 == t0:
            return 60.0 * beats / t0
        k = (t1 - t0) / ramp
        return 60.0 / k * math.log((t0 + k * beats) / t0)

    def _change_at(self, beat):
        c = self.changes[0]
        for ch in self.changes:
            if ch[0] <= beat:
                c = ch
        return c

    def tempo_at(self, beat):
        b0, s, e, ramp, _ = self._change_at(beat)
        x = beat - b0
        if x <= 0.0:
            return s
        if x >= ramp:
            return e
        return s + (e - s) * x / ramp

    def time_at(self, beat):
        b0, s, e, ramp, t0 = self._change_at(beat)
        x = beat - b0
        t = self._ramp_time(s, e, ramp, min(x, ramp))
        if x > ramp:
            t += 60.0 * (x - ramp) / e
        return t0 + t

    def add(self, beat, start, end, ramp):
        if beat == self.changes[-1][0]:
            self.changes[-1] = [beat, start, end, ramp, self.changes[-1][4]]
        else:
            self.changes.append([beat, start, end, ramp, self.time_at(beat)])


# ------------------------------------------------------------------ the performer's state

class Infeasible(Exception):
    pass


class State:
    """What executing the statements so far has built: beat, tempo map, defaults, the notes."""

    def __init__(self):
        self.beat = 0.0
        self.tempo = TempoMap(120.0)
        self.grip = "french"
        self.default_beats = 1.0
        self.default_label = "1 (default)"
        self.default_dynamics = DEFAULT_DYNAMICS
        self.last_time = {"right": None, "left": None}
        self.notes = []

    def copy(self):
        s = State()
        s.beat = self.beat
        s.tempo = self.tempo.copy()
        s.grip = self.grip
        s.default_beats = self.default_beats
        s.default_label = self.default_label
        s.default_dynamics = self.default_dynamics
        s.last_time = dict(self.last_time)
        s.notes = list(self.notes)
        return s

    def time_s(self):
        return self.tempo.time_at(self.beat)

    def hand_free(self, hand, t):
        last = self.last_time[hand]
        return last is None or t - last >= MIN_STROKE_INTERVAL_S + INTERVAL_MARGIN_S

    def execute(self, st):
        """One statement (a dict, see Generator); raises Infeasible if a stroke comes too soon."""
        kind = st["kind"]
        if kind == "note":
            t = self.time_s()
            beats = st["beats"] if st.get("beats") is not None else self.default_beats
            dyn = st["dynamics"] if st.get("dynamics") is not None else self.default_dynamics
            hands = ["right", "left"] if st["hand"] == "both" else [st["hand"]]
            for hand in hands:
                if not self.hand_free(hand, t):
                    raise Infeasible(hand)
            if st.get("ornament"):
                self.add_graces(st, t, dyn)
            for hand in hands:
                self.notes.append({
                    "time_s": t, "hand": hand, "nuance": st.get("nuance") or "legato",
                    "grip": self.grip, "dynamics": dyn, "beats": beats,
                    "tempo_bpm": self.tempo.tempo_at(self.beat), "both": st["hand"] == "both",
                    "r_over_a": st["at"][0] if st.get("at") else DEFAULT_R_OVER_A,
                    "theta_deg": st["at"][1] if st.get("at") else DEFAULT_THETA[hand],
                    "at": bool(st.get("at")),
                    "label": st.get("label") or self.default_label,
                    "ramp": self.in_ramp(), "stmt": st})
                self.last_time[hand] = t
            self.beat += beats
        elif kind == "rest":
            self.beat += st["beats"] if st.get("beats") is not None else self.default_beats
        elif kind == "tempo":
            start = st["start"] if st.get("start") is not None else self.tempo.tempo_at(self.beat)
            self.tempo.add(self.beat, start, st["end"], st.get("ramp", 0.0))
        elif kind == "grip":
            self.grip = st["grip"]
        elif kind == "beats":
            self.default_beats = st["beats"]
            self.default_label = st["label"]
        elif kind == "dynamics":
            self.default_dynamics = st["dynamics"]
        elif kind in ("firmness", "meter"):
            pass  # neither moves a note (the physics plays the firmness: render_check judges it)
        elif kind == "roll":
            self.execute_roll(st)
        elif kind == "repeat":
            for _ in range(st["count"]):
                for inner in st["body"]:
                    self.execute(inner)
        else:
            raise ValueError(kind)

    def add_graces(self, st, t, dyn):
        """A flam's or drag's grace strokes: the other hand's, before the note at t."""
        other = "left" if st["hand"] == "right" else "right"
        leads = [FLAM_LEAD_S] if st["ornament"] == "flam" else \
            [FLAM_LEAD_S + DRAG_SPACING_S, FLAM_LEAD_S]
        if not self.hand_free(other, t - leads[0]):
            raise Infeasible(other)
        for lead in leads:
            self.notes.append({
                "time_s": t - lead, "hand": other, "nuance": "legato", "grip": self.grip,
                "dynamics": min(GRACE_DYNAMICS, 0.5 * dyn), "beats": 0.0,
                "tempo_bpm": self.tempo.tempo_at(self.beat), "both": False,
                "r_over_a": DEFAULT_R_OVER_A, "theta_deg": DEFAULT_THETA[other], "at": False,
                "label": st["ornament"] + " grace", "ramp": self.in_ramp(), "stmt": st,
                "grace": st["ornament"]})
        self.last_time[other] = t - leads[-1]

    def execute_roll(self, st):
        """`roll KIND BEATS`: a stroke at each `beats` subdivision, R L (single, buzz) or R R L L
        (double), each a bare note's (legato, buzz for buzz; the defaults)."""
        count = int(round(st["beats"] / self.default_beats))
        for k in range(count):
            hand = ("right", "left")[(k // 2 if st["roll"] == "double" else k) % 2]
            t = self.time_s()
            if not self.hand_free(hand, t):
                raise Infeasible(hand)
            self.notes.append({
                "time_s": t, "hand": hand, "nuance": "buzz" if st["roll"] == "buzz" else "legato",
                "grip": self.grip, "dynamics": self.default_dynamics, "beats": self.default_beats,
                "tempo_bpm": self.tempo.tempo_at(self.beat), "both": False,
                "r_over_a": DEFAULT_R_OVER_A, "theta_deg": DEFAULT_THETA[hand], "at": False,
                "label": self.default_label, "ramp": self.in_ramp(), "stmt": st})
            self.last_time[hand] = t
            self.beat += self.default_beats

    def in_ramp(self):
        b0, s, e, ramp, _ = self.tempo._change_at(self.beat)
        return s != e and self.beat - b0 < ramp


def count_notes(st):
    if st["kind"] == "note":
        return 2 if st["hand"] == "both" else 1  # a flam's or drag's grace strokes not counted
    if st["kind"] == "roll":
        return st["count"]
    if st["kind"] == "repeat":
        return st["count"] * sum(count_notes(s) for s in st["body"])
    return 0


# ------------------------------------------------------------------ note options

def fmt_num(x, digits=3):
    s = ("%%.%df" % digits) % x
    s = s.rstrip("0").rstrip(".") if "." in s else s
    return s or "0"


def draw_dynamics(rng):
    """(text, value): a word, or a number 0..1 written as Pd or a person writes it."""
    if rng.random() < 0.5:
        word, value = rng.choice(DYNAMICS_WORDS)
        return word, value
    value = round(rng.choice([rng.uniform(0.0, 1.0), 0.0, 1.0, 0.5]), 2)
    text = fmt_num(value, 2)
    r = rng.random()
    if r < 0.15 and 0.0 < value < 1.0:
        text = text.lstrip("0")  # ".5"
    elif r < 0.2 and 0.0 < value:
        text = "%de-2" % round(value * 100)  # an exponent, as Pd may write it
    elif r < 0.23:
        text = "+" + text
    return text, float(text)


def duration_text(rng, num, den):
    """A duration written in one of the forms the parser takes."""
    k = 2 if rng.random() < 0.08 else 1       # a non-reduced form now and then: 2/4
    r = rng.random()
    value = num / den
    if r < 0.6:
        return "%d/%d" % (num * k, den * k)
    if r < 0.8:
        return "beats %d/%d" % (num * k, den * k)
    dec = repr(value)
    if len(dec) <= 6 and float(dec) == value:  # exact decimals only: beats 0.75
        return "beats " + fmt_num(value, 5)
    return "beats %d/%d" % (num, den)


def draw_at(rng):
    r_over_a = round(rng.uniform(0.0, 0.95), 2)
    theta = round(rng.uniform(-180.0, 180.0), 1)
    if rng.random() < 0.15:
        theta += rng.choice([-720.0, -360.0, 360.0, 720.0])  # the parser folds it back
    return r_over_a, theta


# The note options besides the duration: (name, probability, may R+L carry it).
# Each draw function returns (text or None, fields to set in the statement). Add one here.
def _opt_nuance(rng, gen):
    n = rng.choice(gen.nuances)
    text = n
    if n == "vertical_accent" and rng.random() < 0.3:
        text = "vertical-accent"
    if rng.random() < 0.1:
        text = text.upper()
    return text, {"nuance": n}


def _opt_dynamics(rng, gen):
    text, value = draw_dynamics(rng)
    return text, {"dynamics": value}


def _opt_at(rng, gen):
    ra, theta = draw_at(rng)
    return "at %s %s" % (fmt_num(ra, 2), fmt_num(theta, 1)), {"at": (ra, theta)}


NOTE_OPTIONS = [
    ("nuance", 0.85, True, _opt_nuance),
    ("dynamics", 0.6, True, _opt_dynamics),
    ("at", 0.2, False, _opt_at),
]


# ------------------------------------------------------------------ the generator

class Generator:
    # The forms drawn from a stream of their own (grip firmness, flams and drags, rolls, meters),
    # so that a score's other statements stay those drawn without them; the kit's generator
    # draws none of them.
    extended = True

    def __init__(self, seed, nuances):
        self.seed = seed
        self.rng = random.Random(seed)
        self.extra_rng = random.Random(seed * 104729 + 7)
        self.nuances = list(nuances)

    # -- statements (dicts with "kind" and "text"; executed by State)

    def note(self, hand):
        rng = self.rng
        st = {"kind": "note", "hand": hand}
        words = []
        for name, p, both_ok, draw in NOTE_OPTIONS:
            if hand == "both" and not both_ok:
                continue
            if rng.random() < p:
                text, fields = draw(rng, self)
                st.update(fields)
                if text is not None:
                    words.append(text)
        if rng.random() < 0.75:
            num, den, _, label = self.fraction()
            st["beats"] = num / den
            st["label"] = label
            words.append(duration_text(rng, num, den))
        rng.shuffle(words)
        if self.extended:
            x = self.extra_rng
            if x.random() < 0.15:
                words.insert(x.randint(0, len(words)), "firmness " + fmt_num(x.choice(FIRMNESS_VALUES), 2))
            if hand != "both" and x.random() < 0.15:  # the parser refuses a flam on R+L
                st["ornament"] = x.choice(["flam", "drag"])
                words.insert(x.randint(0, len(words)), st["ornament"])
        if hand == "both":
            head = rng.choice(["R+L", "L+R", "both", "r+l"])
        else:
            head = rng.choice({"right": ["R", "R", "R", "right", "r"],
                               "left": ["L", "L", "L", "left", "l"]}[hand])
        st["text"] = " ".join([head] + words)
        return st

    def fraction(self):
        total = sum(f[2] for f in FRACTIONS)
        x = self.rng.uniform(0, total)
        for f in FRACTIONS:
            x -= f[2]
            if x <= 0:
                return f
        return FRACTIONS[-1]

    def tempo_statement(self, state):
        rng = self.rng
        lo, hi = TEMPO_RANGE
        r = rng.random()
        def bpm():
            if rng.random() < 0.15:
                return round(rng.uniform(lo, hi), 1)  # a decimal tempo: "tempo 96.5"
            return float(rng.randint(int(lo), int(hi)))
        arrow = lambda: "->" if rng.random() < 0.8 else "to"  # noqa: E731
        if r < 0.45:
            b = bpm()
            return {"kind": "tempo", "start": b, "end": b, "text": "tempo %s" % fmt_num(b)}
        ramp_beats = rng.choice([1.0, 2.0, 3.0, 4.0, 6.0, 8.0, 0.5, 1.5])
        end = bpm()
        if r < 0.75:
            start = bpm()
            return {"kind": "tempo", "start": start, "end": end, "ramp": ramp_beats,
                    "text": "tempo %s %s %s over %s" % (fmt_num(start), arrow(), fmt_num(end),
                                                        fmt_num(ramp_beats))}
        return {"kind": "tempo", "start": None, "end": end, "ramp": ramp_beats,
                "text": "tempo %s %s over %s" % (arrow(), fmt_num(end), fmt_num(ramp_beats))}

    def rest(self, beats_needed=None):
        rng = self.rng
        if beats_needed is None:
            num, den, _, _ = self.fraction()
            if rng.random() < 0.25:
                return {"kind": "rest", "beats": None, "text": "rest"}
        else:
            fits = [f for f in sorted(FRACTIONS, key=lambda f: f[0] / f[1])
                    if f[0] / f[1] >= beats_needed]
            num, den = (fits[0][0], fits[0][1]) if fits else (int(math.ceil(beats_needed)), 1)
        text = "rest " + (duration_text(rng, num, den) if rng.random() < 0.5 else "%d/%d" % (num, den))
        return {"kind": "rest", "beats": num / den, "text": text}

    def other_statement(self, state):
        rng = self.rng
        if self.extended and self.extra_rng.random() < 0.25:
            x = self.extra_rng
            if x.random() < 0.6:
                f = x.choice(FIRMNESS_VALUES)
                return {"kind": "firmness", "firmness": f, "text": "firmness " + fmt_num(f, 2)}
            num, den = x.choice(METERS)
            return {"kind": "meter", "text": "meter %d/%d" % (num, den)}
        r = rng.random()
        if r < 0.35:
            return self.tempo_statement(state)
        if r < 0.55:
            g = rng.choice(GRIPS)
            return {"kind": "grip", "grip": g, "text": "grip " + g}
        if r < 0.75:
            num, den, _, label = self.fraction()
            return {"kind": "beats", "beats": num / den, "label": label,
                    "text": "beats " + duration_text(rng, num, den).replace("beats ", "")}
        text, value = draw_dynamics(rng)
        return {"kind": "dynamics", "dynamics": value, "text": "dynamics " + text}

    def pick_hand(self, prev_hand):
        r = self.rng.random()
        if prev_hand is None:
            return self.rng.choice(["right", "left", "both"]) if r < 0.9 else "both"
        if r < 0.12:
            return "both"
        if r < 0.62:
            return {"right": "left", "left": "right", "both": self.rng.choice(["right", "left"])}[prev_hand]
        return self.rng.choice(["right", "left"])

    def place_note(self, state, st):
        """Execute a note on `state`, repairing it to keep the planner's rule: the other hand,
        else a rest first. Returns the statements actually emitted."""
        trial = state.copy()
        try:
            trial.execute(st)
            state.__dict__.update(trial.__dict__)
            return [st]
        except Infeasible:
            pass
        if st["hand"] in ("right", "left"):
            other = "left" if st["hand"] == "right" else "right"
            swapped = dict(st, hand=other, text=self.swap_hand_text(st["text"], other))
            trial = state.copy()
            try:
                trial.execute(swapped)
                state.__dict__.update(trial.__dict__)
                return [swapped]
            except Infeasible:
                pass
        # A rest long enough for every hand the note needs.
        needs = ["right", "left"] if st["hand"] == "both" else [st["hand"]]
        # A flam's or drag's grace hand needs its time before the note's grace strokes.
        lead = {"flam": FLAM_LEAD_S, "drag": FLAM_LEAD_S + DRAG_SPACING_S}.get(st.get("ornament"))
        if lead:
            needs.append("left" if st["hand"] == "right" else "right")
        t_need = max(state.last_time[h] + (lead if lead and h not in needs[:1] else 0.0)
                     for h in needs if state.last_time[h] is not None) \
            + MIN_STROKE_INTERVAL_S + 2 * INTERVAL_MARGIN_S
        beats_needed = 1.0 / 32.0
        while True:
            probe = state.copy()
            probe.beat += beats_needed
            if probe.time_s() >= t_need:
                break
            beats_needed *= 1.25
        rest = self.rest(beats_needed)
        state.execute(rest)
        state.execute(st)  # cannot fail now
        return [rest, st]

    @staticmethod
    def swap_hand_text(text, hand):
        head, _, rest = text.partition(" ")
        new = {"right": "R", "left": "L"}[hand]
        return (new + " " + rest).strip()

    def make_repeat(self, state, notes_left):
        rng = self.rng
        count = rng.choice([2, 2, 3])
        body_len = rng.randint(1, 3)
        body = []
        hand = None
        for _ in range(body_len):
            if rng.random() < 0.15:
                body.append(self.other_statement(state))
            hand = self.pick_hand(hand)
            if rng.random() < 0.15 and hand != "both":  # a nested repeat of one stroke
                body.append({"kind": "repeat", "count": 2, "body": [self.note(hand)]})
            else:
                body.append(self.note(hand))
        rep = {"kind": "repeat", "count": count, "body": body}
        if self.count_notes(rep) > notes_left:
            return None
        for attempt in range(6):
            trial = state.copy()
            try:
                trial.execute(rep)
                state.__dict__.update(trial.__dict__)
                return rep
            except Infeasible:
                body.append(self.rest())
        return None

    def make_roll(self, state, notes_left):
        """`roll single|double|buzz BEATS`: 2..6 strokes at the `beats` default (a whole number
        of them: BEATS written as a fraction of it), or None when a stroke would come too soon."""
        x = self.extra_rng
        kind = x.choice(ROLLS)
        count = min(x.randint(2, 6), notes_left)
        if count < 2:
            return None
        from fractions import Fraction
        sub = Fraction(state.default_beats).limit_denominator(96)
        total = sub * count
        if not Fraction(1, 32) <= total <= 64:
            return None
        st = {"kind": "roll", "roll": kind, "beats": float(total), "count": count,
              "text": "roll %s %s" % (kind, "%d/%d" % (total.numerator, total.denominator)
                                      if total.denominator > 1 else "%d" % total.numerator)}
        trial = state.copy()
        try:
            trial.execute(st)
        except Infeasible:
            return None
        state.__dict__.update(trial.__dict__)
        return st

    count_notes = staticmethod(count_notes)
    new_state = State

    def generate(self):
        rng = self.rng
        state = self.new_state()
        out = []   # top-level statements
        first_tempo = rng.randint(int(TEMPO_RANGE[0]), int(TEMPO_RANGE[1]))  # whole bpm
        if rng.random() < 0.3:
            st = self.tempo_statement(state)  # may ramp, "tempo -> X" from the default 120
        else:
            st = {"kind": "tempo", "start": float(first_tempo), "end": float(first_tempo),
                  "text": "tempo %d" % first_tempo}
        state.execute(st)
        out.append(st)
        if rng.random() < 0.85:
            g = rng.choice(GRIPS)
            st = {"kind": "grip", "grip": g, "text": "grip " + g}
            state.execute(st)
            out.append(st)
        target = rng.randint(*NOTES_RANGE)
        hand = None
        notes = 0
        while notes < target:
            if state.time_s() > SCORE_BUDGET_S and notes >= NOTES_RANGE[0]:
                break
            r = rng.random()
            if r < 0.12:
                st = self.other_statement(state)
                if st["kind"] == "beats" and state.time_s() > SCORE_BUDGET_S / 2:
                    continue  # long defaults late in the score only lengthen it
                state.execute(st)
                out.append(st)
                continue
            if r < 0.18 and notes > 0:
                st = self.rest()
                state.execute(st)
                out.append(st)
                continue
            if r < 0.26 and target - notes >= 2:
                rep = self.make_repeat(state, target - notes)
                if rep is not None:
                    out.append(rep)
                    notes += self.count_notes(rep)
                    hand = None
                    continue
            if self.extended and self.extra_rng.random() < 0.06 and target - notes >= 2:
                roll = self.make_roll(state, target - notes)
                if roll is not None:
                    out.append(roll)
                    notes += roll["count"]
                    hand = None
                    continue
            hand = self.pick_hand(hand)
            st = self.note(hand)
            if notes + self.count_notes(st) > NOTES_RANGE[1]:
                hand = rng.choice(["right", "left"])
                st = self.note(hand)
            emitted = self.place_note(state, st)
            out.extend(emitted)
            notes += self.count_notes(emitted[-1])
            hand = emitted[-1]["hand"]
        self.state = state
        self.statements = out
        return out

    # -- text

    def render_text(self, statements):
        rng = self.rng
        lines = ["# random score, seed %d (ictus_tools.random_score)" % self.seed]
        pending = []

        def flush():
            if pending:
                sep = rng.choice([", ", ", ", "; ", " , "])
                lines.append(sep.join(pending))
                pending.clear()

        def emit(st, depth):
            if st["kind"] == "repeat":
                flush()
                lines.append("repeat %d" % st["count"])
                for inner in st["body"]:
                    emit(inner, depth + 1)
                flush()
                lines.append("end")
                return
            text = st["text"]
            if rng.random() < 0.05:
                text = text.upper()
            st["line"] = len(lines) + 1
            pending.append(text)
            if rng.random() < 0.45 or len(pending) >= 4:
                flush()
                if rng.random() < 0.08:
                    lines[-1] += "  # a comment, ignored"

        for st in statements:
            emit(st, 0)
        flush()
        return "\n".join(lines) + "\n"


LIMB_ORDER = {"right": 0, "left": 1, "right-foot": 2, "left-foot": 3}  # notes.csv's order on a beat


class RandomScore:
    """A generated score: `text`, the `notes` it must give (time_s from beat 0, hand -- a limb
    on a kit, `right-foot` too --, nuance, grip, dynamics, beats, tempo_bpm, r_over_a,
    theta_deg, features; on a kit its `drum`), `length_s`. `kit` ("full"): a score over that
    kit (ictus_tools.random_kit_score), rendered with `--kit KIT`; None: on the one drum."""

    def __init__(self, seed, nuances=None, kit=None):
        self.seed = seed
        self.kit = kit
        self.nuances = list(nuances) if nuances else nuance_list()
        if kit:
            from ictus_tools.random_kit_score import KitGenerator
            gen = KitGenerator(seed, self.nuances, kit)
        else:
            gen = Generator(seed, self.nuances)
        statements = gen.generate()
        self.text = gen.render_text(statements)
        self.notes = sorted(gen.state.notes, key=lambda n: (n["time_s"], LIMB_ORDER[n["hand"]]))
        self.length_s = gen.state.time_s()
        self.physical_grip = next((n["grip"] for n in self.notes if n["grip"]), "french")
        for n in self.notes:
            n["line"] = n.pop("stmt")["line"]
            n["features"] = note_features(n, self.notes)

    def write(self, path):
        with open(path, "w") as f:
            f.write(self.text)


def tempo_band(bpm):
    for hi, name in ((70, "40-69"), (100, "70-99"), (130, "100-129"), (160, "130-159"),
                     (190, "160-189")):
        if bpm < hi:
            return name
    return "190-220"


def interval_band(s):
    if s is None:
        return "first"
    for hi, name in ((0.15, "0.10-0.15"), (0.2, "0.15-0.2"), (0.3, "0.2-0.3"), (0.5, "0.3-0.5"),
                     (1.0, "0.5-1"), (2.0, "1-2")):
        if s < hi:
            return name
    return ">=2"


def note_features(n, notes):
    """The features a failure is counted under (bench/random_scores.py)."""
    same = [m["time_s"] for m in notes if m["hand"] == n["hand"] and m["time_s"] < n["time_s"]]
    prev = [m for m in notes if m["hand"] == n["hand"] and m["time_s"] < n["time_s"]]
    other = [m["time_s"] for m in notes if m["hand"] != n["hand"] and m["time_s"] <= n["time_s"]
             and m is not n]
    gap = n["time_s"] - max(same) if same else None
    nxt = [m["time_s"] for m in notes if m["hand"] == n["hand"] and m["time_s"] > n["time_s"]]
    gap_next = min(nxt) - n["time_s"] if nxt else None
    other_gap = n["time_s"] - max(other) if other else None
    d = n["dynamics"]
    kit = {"drum": n["drum"]} if "drum" in n else {}
    return kit | {
        "tempo": tempo_band(n["tempo_bpm"]),
        "ramp": "in ramp" if n["ramp"] else "steady",
        "fraction": n["label"],
        "grip": n["grip"],
        "sticks' grip": notes[0]["grip"] if notes else n["grip"],
        "previous stroke": prev[-1]["nuance"] if prev else "none",
        "nuance": n["nuance"],
        "dynamics": "pp-p (<0.35)" if d < 0.35 else "mp-mf (<0.7)" if d < 0.7 else "f-ff",
        "hands": "R+L" if n["both"] else "one",
        "hand": n["hand"],
        "at": ("r/a %.1f-%.1f" % (math.floor(n["r_over_a"] * 5) / 5, math.floor(n["r_over_a"] * 5) / 5 + 0.2))
              if n["at"] else "default spot",
        "gap before (s)": interval_band(gap),
        "gap after (s)": interval_band(gap_next) if gap_next is not None else "last",
        "other hand before (s)": "none" if other_gap is None else
            "<0.03" if other_gap < 0.03 else "0.03-0.1" if other_gap < 0.1 else ">=0.1",
    }


# What --coverage counts: the score language's forms, as regular expressions on the text
# (case-insensitive; one statement per match, statements split at , ; and newlines).
COVERAGE = [
    ("hand R / right", r"^(r|right)\b(?!\+)"), ("hand L / left", r"^(l|left)\b(?!\+)"),
    ("R+L / L+R / both", r"^(r\+l|l\+r|both)\b"),
    ("tempo BPM", r"^tempo [0-9.]+$"), ("tempo BPM -> BPM over B", r"^tempo [0-9.]+ (->|to) "),
    ("tempo -> BPM over B (from the current tempo)", r"^tempo (->|to) "),
    ("'to' for '->'", r"^tempo .*\bto\b"), ("decimal tempo", r"^tempo .*\d\.\d"),
    ("grip french", r"^grip french$"), ("grip german", r"^grip german$"),
    ("rest", r"^rest$"), ("rest N/D", r"^rest \d+/\d+$"), ("rest beats X", r"^rest beats "),
    ("beats X (default duration)", r"^beats "), ("dynamics D (default)", r"^dynamics "),
    ("repeat N ... end", r"^repeat \d+$"),
    ("note N/D", r"^(r|l|right|left|r\+l|l\+r|both)\b.* \d+/\d+\b"),
    ("note beats X", r"^(r|l|right|left|r\+l|l\+r|both)\b.* beats "),
    ("note beats decimal", r"^(r|l|right|left|r\+l|l\+r|both)\b.* beats \d*\.\d"),
    ("triplet (N/3, N/6, N/12)", r" (beats )?\d+/(3|6|12)\b"),
    ("dotted (3/2, 3/4, 3/8, 3/16, 7/8)", r" (beats )?(3/2|3/4|3/8|3/16|7/8|6/4|6/8|6/16|6/32|14/16)\b"),
    ("1/32", r" (beats )?(1/32|2/64)\b"), ("at R/A THETA", r" at [0-9.]+ -?[0-9.]+"),
    ("dynamics word", r"^(r|l|right|left|r\+l|l\+r|both)\b.* (pp|p|mp|mf|f|ff)\b"),
    ("dynamics number", r"^(r|l|right|left|r\+l|l\+r|both)\b.* [+]?[0-9]*\.?[0-9]+(e-2)?( |$)"),
    ("dynamics .5 / 5e-2 / +0.5", r" (\.[0-9]|[0-9]+e-2|\+[0-9])"),
    ("vertical-accent spelling", r"vertical-accent"), ("upper case", r"[A-Z]{2,}"),
    ("firmness F (default)", r"^firmness [0-9.]+$"),
    ("note firmness F", r"^(r|l|right|left|r\+l|l\+r|both)\b.* firmness [0-9.]+"),
    ("flam", r"^(r|l|right|left)\b.* flam\b"), ("drag", r"^(r|l|right|left)\b.* drag\b"),
    ("roll single", r"^roll single "), ("roll double", r"^roll double "),
    ("roll buzz", r"^roll buzz "), ("meter N/D", r"^meter \d+/\d+$"),
]


def coverage(count, nuances):
    """How many of seeds 1..count hold each form (and each nuance)."""
    hits = {name: 0 for name, _ in COVERAGE}
    nuance_hits = {n: 0 for n in nuances}
    nested = separators = comments = wrapped = 0
    for seed in range(1, count + 1):
        sc = RandomScore(seed, nuances)
        stmts = []
        depth = max_depth = 0
        for line in sc.text.split("\n"):
            if "#" in line and not line.startswith("#"):
                comments += 1
            line = line.split("#")[0]
            if ";" in line or "," in line:
                separators += 1
            stmts.extend(x.strip() for x in re.split(r"[,;]", line) if x.strip())
        for st in stmts:
            if re.match(r"^repeat", st, re.I):
                depth += 1
                max_depth = max(max_depth, depth)
            elif re.match(r"^end$", st, re.I):
                depth -= 1
        nested += max_depth >= 2
        wrapped += any(m["at"] and not -180.0 < m["theta_deg"] <= 180.0 for m in sc.notes)
        for name, rx in COVERAGE:
            flags = 0 if name == "upper case" else re.I
            if any(re.search(rx, st, flags) for st in stmts):
                hits[name] += 1
        for n in nuance_hits:
            if any(m["nuance"] == n for m in sc.notes):
                nuance_hits[n] += 1
    out = ["scores (seeds 1..%d) holding each form:" % count]
    out += ["  %-50s %d" % (k, v) for k, v in hits.items()]
    out += ["  %-50s %d" % ("at, theta outside (-180, 180]", wrapped),
            "  %-50s %d" % ("nested repeat", nested),
            "  %-50s %d" % ("lines with , or ; separators", separators),
            "  %-50s %d" % ("end-of-line comments", comments)]
    out += ["  %-50s %d" % ("nuance " + k, v) for k, v in nuance_hits.items()]
    return "\n".join(out) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seed", type=int)
    ap.add_argument("--coverage", type=int, metavar="N",
                    help="instead: how many of seeds 1..N hold each form of the language")
    ap.add_argument("--ictusd", help="read the nuance list from this ictusd's parser")
    ap.add_argument("--notes", action="store_true", help="also print the expected notes (as comments)")
    ap.add_argument("--kit", help="a score over this kit (full), rendered with --kit KIT")
    args = ap.parse_args(argv)
    if args.coverage:
        sys.stdout.write(coverage(args.coverage, nuance_list(args.ictusd)))
        return 0
    if args.seed is None:
        ap.error("--seed N is required (or --coverage N)")
    score = RandomScore(args.seed, nuance_list(args.ictusd), kit=args.kit)
    sys.stdout.write(score.text)
    if args.notes:
        for n in score.notes:
            sys.stdout.write("# note t=%.6f s (plan %.6f) %-5s %s %s dyn %.2f beats %.4f tempo %.1f%s\n"
                             % (n["time_s"], n["time_s"] + LEAD_IN_S, n["hand"], n["nuance"],
                                n["grip"], n["dynamics"], n["beats"], n["tempo_bpm"],
                                " on " + n["drum"] if "drum" in n else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
