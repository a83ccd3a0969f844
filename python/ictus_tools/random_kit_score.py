"""Seeded random scores over a kit (docs/kit.md), valid ones only: the kit mode of
ictus_tools.random_score (`RandomScore(seed, nuances, kit="full")`, `random_score --kit full`).

    python3 -m ictus_tools.random_score --seed N --kit full --notes

Everything the one-drum generator draws (tempi and ramps, fractions, rests, `beats` and
`dynamics` defaults, grips, nuances, dynamics, repeats; random_score's docstring), and the kit's
words (docs/score.md): `drum NAME` statements, `on NAME` on a note, the hi-hat's `open`, `half`
and `closed` (on a hi-hat note only, by `on hihat` or after `drum hihat`), `at R/A THETA` on a
head and on the ride (its bell near r/a 0), `R+L` on the snare and rack toms, the right foot's
`RF` / `right-foot` on the kick (dynamics, a duration, sometimes `on kick`; no flam, `at`,
firmness or openness: the parser refuses them), and chords `A + B [+ C]` of two or three limbs,
each limb once, each part with its own options; a chord lasts its longest written duration and
a part without one as long as the chord. A kit score is rendered with `ictusd render --kit KIT`.

Validity, by construction, with the generator's own tempo map (random_score.TempoMap):
- a hand's strokes >= MIN_STROKE_INTERVAL_S (0.1 s) apart, as on the one drum; the right
  foot's >= KICK_MIN_INTERVAL_S (the planner refuses kicks closer than 60 ms; 70 ms is above
  the pedal's measured tightest double, 38..54 ms, docs/pedal.md); a note whose limb would
  come too soon gets a rest first (a repeat that would break the rule gets rests in its body);
- no hand's note on the kick (`drum kick` is never written: the hands' drum), no pedal word on
  a piece that is not the hi-hat, no `drum`/`on` outside the kit.

What a hand is not asked to play, because docs/kit.md documents it as beyond the performer:
- the right hand on the crash ("The hi-hat": too far left for it, missed) -- REACH below;
  the left hand on the floor tom and the ride ("Random kit scores": in a first draw that
  allowed them, 7 of the left's ride notes missed or 6..15 ms late);
- crossed arms on one beat: in a chord the left hand's piece is left of the right's, but for
  the groove's right hand on the hi-hat over the left on the snare (`uncrossed`);
- a move to another piece sooner than MOVE_BASE_S + MOVE_S_PER_M x the distance between the
  pieces' places after the hand's last stroke ("The song": the right hand from the ride to
  the hi-hat, 1.0 m, in 250 ms is 13.5 ms late; the left from the floor tom to the crash,
  1.1 m in 250 ms, 31 ms late);
- `at` on a drum far from the hand's side (the stick keeps the rest direction's yaw, "Not
  done": the far right of the floor tom is a long reach): THETA within AT_SPREAD_DEG of the
  hand's default side, r/a <= 0.6; on the ride its bell (r/a <= 0.2); none on the hi-hat and
  crash (played on their bow, "Cymbals").
"""
import math
import random

from ictus_tools import random_score as rs

# The limbs a kit score writes: the hands, the right foot on the kick and the left foot's chick
# on the hi-hat (`LF`); each foot's notes at least its interval apart (the planner's 60 ms for
# the kick, 100 ms for the chick, docs/pedal.md, with a margin).
LIMBS = ["right", "left", "right-foot", "left-foot"]
LIMB_HEADS = {"right": ["R", "R", "right", "r"], "left": ["L", "L", "left", "l"],
              "right-foot": ["RF", "RF", "right-foot", "rf"],
              "left-foot": ["LF", "LF", "left-foot", "lf"]}
FOOT_LIMBS = {"right-foot": "kick", "left-foot": "hihat"}  # a foot and the piece it plays
KICK_MIN_INTERVAL_S = 0.07
FOOT_MIN_INTERVAL_S = {"right-foot": KICK_MIN_INTERVAL_S, "left-foot": 0.11}

# The kits: each hand piece's place (x right, y up, z forward, m; docs/kit.md's table).
KITS = {
    "full": {"snare": (0.0, 0.0, 0.0), "tom1": (-0.15, 0.23, 0.30), "tom2": (0.19, 0.21, 0.32),
             "floor": (0.56, 0.0, -0.20), "crash": (-0.64, 0.30, 0.36),
             "ride": (0.62, 0.22, 0.28), "hihat": (-0.42, 0.26, -0.02)},
}
HIHAT = "hihat"
CYMBALS = {"crash", "ride", "hihat"}
REACH = {"right": ["snare", "tom1", "tom2", "floor", "ride", "hihat"],  # not the crash
         "left": ["snare", "tom1", "tom2", "hihat", "crash"]}           # not the floor, ride
BOTH_DRUMS = ["snare", "tom1", "tom2"]        # R+L: both sticks on one head
MOVE_BASE_S = 0.1
MOVE_S_PER_M = 0.35
AT_SPREAD_DEG = 60.0
OPENNESS = ["open", "half", "closed"]


def move_interval_s(kit, a, b):
    """The least time between a hand's strokes on pieces a and b (a None: from rest)."""
    if a is None or a == b:
        return rs.MIN_STROKE_INTERVAL_S
    pa, pb = KITS[kit][a], KITS[kit][b]
    return max(rs.MIN_STROKE_INTERVAL_S, MOVE_BASE_S + MOVE_S_PER_M * math.dist(pa, pb))


def uncrossed(kit, left, right):
    """Two hands on one beat without crossed arms: the left hand's piece left of the right's,
    or the right crossed over to the hi-hat above the left on the snare (a groove's hands)."""
    return KITS[kit][left][0] < KITS[kit][right][0] or (right == HIHAT and left == "snare")


class KitState(rs.State):
    """random_score.State with the kit: the hands' current drum, each limb's last stroke and
    piece. A note statement holds `parts` (one per limb: a chord has two or three)."""

    def __init__(self, kit="full"):
        super().__init__()
        self.kit = kit
        self.drum = None                    # the `drum` statement's; None: the kit's first
        self.last_time = {limb: None for limb in LIMBS}
        self.last_piece = {limb: None for limb in LIMBS}

    def copy(self):
        s = KitState(self.kit)
        s.__dict__.update(super().copy().__dict__)
        s.kit, s.drum = self.kit, self.drum
        s.last_time = dict(self.last_time)
        s.last_piece = dict(self.last_piece)
        return s

    def first_drum(self):
        return next(iter(KITS[self.kit]))

    def piece_of(self, part):
        if part["limb"] in FOOT_LIMBS:
            return FOOT_LIMBS[part["limb"]]
        return part.get("drum") or self.drum or self.first_drum()

    def free(self, limb, t, piece):
        last = self.last_time[limb]
        if last is None:
            return True
        if limb in FOOT_LIMBS:
            need = FOOT_MIN_INTERVAL_S[limb]
        else:
            need = move_interval_s(self.kit, self.last_piece[limb], piece)
        return t - last >= need + rs.INTERVAL_MARGIN_S

    def execute(self, st):
        if st["kind"] == "drum":
            self.drum = st["drum"]
            return
        if st["kind"] != "note":
            super().execute(st)
            return
        t = self.time_s()
        written = [p["beats"] for p in st["parts"] if p.get("beats") is not None]
        chord_beats = max(written) if written else self.default_beats
        played = []
        for part in st["parts"]:
            piece = self.piece_of(part)
            hands = ["right", "left"] if part["limb"] == "both" else [part["limb"]]
            for limb in hands:
                if not self.free(limb, t, piece):
                    raise rs.Infeasible(limb)
                played.append((limb, piece, part))
        for limb, piece, part in played:
            foot = limb in FOOT_LIMBS
            at = part.get("at")
            self.notes.append({
                "time_s": t, "hand": limb, "drum": piece,
                "nuance": "" if foot else part.get("nuance") or "legato",
                "grip": "" if foot else self.grip,
                "dynamics": part["dynamics"] if part.get("dynamics") is not None
                else self.default_dynamics,
                "beats": part["beats"] if part.get("beats") is not None else chord_beats,
                "tempo_bpm": self.tempo.tempo_at(self.beat), "both": part["limb"] == "both",
                "chord": len(st["parts"]) > 1, "openness": part.get("openness"),
                "r_over_a": at[0] if at else rs.DEFAULT_R_OVER_A,
                "theta_deg": at[1] if at else rs.DEFAULT_THETA.get(limb, 0.0), "at": bool(at),
                "label": part.get("label") or (self.default_label if not written else "chord"),
                "ramp": self.in_ramp(), "stmt": st})
            self.last_time[limb] = t
            self.last_piece[limb] = piece
        self.beat += chord_beats


class KitGenerator(rs.Generator):
    """random_score.Generator over a kit: its notes are limbs' parts on the kit's pieces."""

    extended = False  # no grip firmness, flams, drags, rolls or meters (random_score's)

    def __init__(self, seed, nuances, kit="full"):
        if kit not in KITS:
            raise ValueError("no random scores for kit %r (known: %s)" % (kit, ", ".join(KITS)))
        super().__init__(seed, nuances)
        # The pieces' other names (`ride-bell`, `floor-tom`, `hi-hat`, `bass-drum`: docs/score.md)
        # from a stream of their own, so that the scores are otherwise those drawn without them.
        self.spell_rng = random.Random(seed * 7919 + 17)
        self.kit = kit
        self.current_drum = None  # the `drum` statement's as the statements are drawn
        self.in_repeat = False
        self.chord_left = self.chord_right = None  # the hands' pieces in the chord being drawn

    def new_state(self):
        return KitState(self.kit)

    @staticmethod
    def count_notes(st):
        if st["kind"] == "note":
            return sum(2 if p["limb"] == "both" else 1 for p in st["parts"])
        if st["kind"] == "repeat":
            return st["count"] * sum(KitGenerator.count_notes(s) for s in st["body"])
        return 0

    # -- statements

    def make_repeat(self, state, notes_left):
        # No `drum` statement in a repeat's body: a later pass would play the body's notes
        # without `on` on another drum than they were drawn for (an openness off the hi-hat).
        self.in_repeat = True
        try:
            return super().make_repeat(state, notes_left)
        finally:
            self.in_repeat = False

    def other_statement(self, state):
        if not self.in_repeat and self.rng.random() < 0.3:
            drum = self.rng.choice(list(KITS[self.kit]))
            self.current_drum = drum
            return {"kind": "drum", "drum": drum,
                    "text": "drum " + (drum.upper() if self.rng.random() < 0.1 else drum)}
        return super().other_statement(state)

    def pick_hand(self, prev_hand):
        r = self.rng.random()
        if r < 0.3:
            return "chord"
        if r < 0.4:
            return "right-foot"
        if r < 0.45:
            return "left-foot"
        if r < 0.52:
            return "both"
        if prev_hand in ("right", "left") and self.rng.random() < 0.5:
            return {"right": "left", "left": "right"}[prev_hand]
        return self.rng.choice(["right", "left"])

    def note(self, hand):
        """A note statement: one limb's note (`hand` a limb or "both"), or a chord ("chord")."""
        rng = self.rng
        if hand == "chord":
            limbs = rng.choice([["right", "left"], ["right", "right-foot"], ["left", "right-foot"],
                                ["right", "left", "right-foot"], ["right", "left", "right-foot"],
                                ["right", "left-foot"], ["right", "right-foot", "left-foot"],
                                ["right", "left", "right-foot", "left-foot"]])
            parts, taken = [], set()
            self.chord_left = self.chord_right = None
            for limb in limbs:
                parts.append(self.part(limb, chord=True, taken=taken))
                piece = parts[-1].get("piece")
                if limb == "left":
                    self.chord_left = piece
                elif limb == "right":
                    self.chord_right = piece
            self.chord_left = self.chord_right = None
            rng.shuffle(parts)
            text = " + ".join(p["text"] for p in parts)
        else:
            parts = [self.part(hand)]
            text = parts[0]["text"]
        return {"kind": "note", "hand": hand, "parts": parts, "text": text}

    def part(self, limb, chord=False, taken=None):
        """One limb's note: its options drawn and written in a random order."""
        rng = self.rng
        p = {"limb": limb}
        words = []
        foot = limb in FOOT_LIMBS
        if foot:
            if rng.random() < 0.2:
                words.append("on " + self.spelled(FOOT_LIMBS[limb]))
        else:
            drum = self.draw_piece(limb, chord, taken or set())
            if taken is not None:
                taken.add(drum)
            current = self.current_drum or next(iter(KITS[self.kit]))
            if drum != current or rng.random() < 0.4:
                p["drum"] = drum
                words.append("on " + self.spelled(drum))
            piece = p["piece"] = drum
            if rng.random() < 0.85:
                text, fields = rs._opt_nuance(rng, self)
                p.update(fields)
                words.append(text)
            if piece == HIHAT and rng.random() < 0.6:
                p["openness"] = rng.choice(OPENNESS)
                words.append(p["openness"])
            if limb != "both" and piece not in CYMBALS - {"ride"} and \
                    rng.random() < (0.4 if piece == "ride" else 0.2):
                p["at"] = self.draw_at(limb, piece)
                words.append("at %s %s" % (rs.fmt_num(p["at"][0], 2), rs.fmt_num(p["at"][1], 1)))
            elif piece == "ride" and "on ride" in words and self.spell_rng.random() < 0.3:
                words[words.index("on ride")] = "on ride-bell"  # its bell, at no `at`
        if rng.random() < (0.7 if foot else 0.6):
            text, p["dynamics"] = rs.draw_dynamics(rng)
            words.append(text)
        if rng.random() < (0.45 if chord else 0.7):
            num, den, _, label = self.fraction()
            p["beats"], p["label"] = num / den, label
            words.append(rs.duration_text(rng, num, den))
        rng.shuffle(words)
        if limb == "both":
            head = rng.choice(["R+L", "L+R", "both"])
        else:
            head = rng.choice(LIMB_HEADS[limb])
        p["text"] = " ".join([head] + words)
        return p

    def draw_piece(self, limb, chord, taken):
        """A piece the hand (or both hands) reaches: the current drum now and then, never one
        the other hand of the chord plays."""
        rng = self.rng
        allowed = BOTH_DRUMS if limb == "both" else REACH[limb]
        allowed = [d for d in allowed if d not in taken]
        if limb == "left" and self.chord_right:  # the left's piece left of the right's
            allowed = [d for d in allowed if uncrossed(self.kit, d, self.chord_right)]
        elif limb == "right" and self.chord_left:
            allowed = [d for d in allowed if uncrossed(self.kit, self.chord_left, d)]
        current = self.current_drum or next(iter(KITS[self.kit]))
        if current in allowed and rng.random() < 0.4:
            return current
        return rng.choice(allowed)

    # The other names of the full kit's pieces that a score may write (docs/score.md).
    SPELLINGS = {"floor": ["floor-tom", "floor_tom", "floortom"], "hihat": ["hi-hat", "hi_hat"],
                 "kick": ["bass-drum", "bass_drum", "bassdrum"]}

    def spelled(self, piece):
        """The piece's name as the score writes it: now and then another of its names."""
        other = self.SPELLINGS.get(piece)
        if other and self.spell_rng.random() < 0.25:
            return self.spell_rng.choice(other)
        return piece

    def draw_at(self, limb, piece):
        rng = self.rng
        if piece == "ride":
            return round(rng.uniform(0.0, 0.2), 2), round(rng.uniform(-180.0, 180.0), 1)
        side = rs.DEFAULT_THETA[limb]
        theta = side + rng.uniform(-AT_SPREAD_DEG, AT_SPREAD_DEG)
        theta = (theta + 180.0) % 360.0 - 180.0
        if rng.random() < 0.1:
            theta += rng.choice([-360.0, 360.0])  # the parser folds it back
        return round(rng.uniform(0.0, 0.6), 2), round(theta, 1)

    def place_note(self, state, st):
        """Execute a note on `state`; if a limb would come too soon, a rest first, long enough
        for every limb of it (found on the tempo map by trial)."""
        trial = state.copy()
        try:
            trial.execute(st)
            state.__dict__.update(trial.__dict__)
            return [st]
        except rs.Infeasible:
            pass
        beats = 1.0 / 32.0
        while True:
            rest = self.rest(beats)
            trial = state.copy()
            trial.execute(rest)
            try:
                trial.execute(st)
                state.__dict__.update(trial.__dict__)
                return [rest, st]
            except rs.Infeasible:
                beats = rest["beats"] * 1.25
