"""What one corpus item is made of: its parameters, drawn from documented distributions
(docs/corpus.md, "Distributions"), seeded from (seed, index) alone so that item k is the same
whatever --count is, and its split (train/validation/test) from a hash of (seed, index)."""
import hashlib
import random

from ictus_tools.random_score import RandomScore

# the drum presets and their tensions, N/m (externals/core/membrane_presets.c, docs/sound.md)
PRESET_TENSION = {"paper": 3000.0, "snare": 3603.0, "tom": 1465.7, "floor-tom": 878.0,
                  "timpani": 1493.0, "frame": 599.0}
DRUM_PRESETS = list(PRESET_TENSION)
STICK_TIPS = ["wood", "nylon", "felt"]
GRIPS = ["french", "german"]
METERS = [(4, 4, 6), (3, 4, 3), (2, 4, 2), (6, 8, 2), (5, 4, 1), (7, 8, 1)]  # (N, D, weight)
DYNAMICS = ["pp", "p", "mp", "mf", "f", "ff"]
TENSION_SCALE = (0.8, 1.25)     # x the preset's tension, log-uniform
HUMANIZE_P = 0.5                # P(humanize on)
HUMANIZE_RANGE = (0.0, 1.0)     # its amount, uniform
HAIRPIN_P = 0.5                 # P(a hairpin at beat 0)
HAIRPIN_BEATS = (1, 8)          # its length in beats, uniform integer
SPLITS = (("train", 0.8), ("validation", 0.1), ("test", 0.1))


def item_rng(seed, index):
    """The item's own generator: Python's Random seeded with a string (hashed with SHA-512 by
    Python, the same on every machine and run)."""
    return random.Random("ictus-corpus:%d:%d" % (seed, index))


def split_of(seed, index):
    """train / validation / test from SHA-256 of (seed, index): an item keeps its split when the
    corpus grows."""
    h = hashlib.sha256(("ictus-corpus-split:%d:%d" % (seed, index)).encode()).digest()
    u = int.from_bytes(h[:8], "big") / 2.0 ** 64
    acc = 0.0
    for name, p in SPLITS:
        acc += p
        if u < acc:
            return name
    return SPLITS[-1][0]


def draw(seed, index, nuances=None):
    """The parameters of item `index` of the corpus of `seed`: a dict of plain values (the
    manifest's columns), the score text and the score's length in seconds."""
    rng = item_rng(seed, index)
    score_seed = rng.randrange(1, 2 ** 31)
    score = RandomScore(score_seed, nuances)
    n, d, _ = rng.choices(METERS, weights=[m[2] for m in METERS])[0]
    lines = ["# ictus-corpus seed %d item %d (random score %d)" % (seed, index, score_seed),
             "meter %d/%d" % (n, d)]
    hairpin = ""
    if rng.random() < HAIRPIN_P:
        a, b = rng.sample(DYNAMICS, 2)
        hairpin = "%s -> %s over %d" % (a, b, rng.randint(*HAIRPIN_BEATS))
        lines.append("dynamics " + hairpin)
    text = "\n".join(lines) + "\n" + score.text
    preset = rng.choice(DRUM_PRESETS)
    lo, hi = TENSION_SCALE
    tension_scale = round(lo * (hi / lo) ** rng.random(), 4)
    humanize = round(rng.uniform(*HUMANIZE_RANGE), 3) if rng.random() < HUMANIZE_P else 0.0
    params = {
        "index": index,
        "score_source": "random_score",
        "score_seed": score_seed,
        "meter": "%d/%d" % (n, d),
        "hairpin": hairpin,
        "drum_preset": preset,
        "tension_scale": tension_scale,
        "tension_n_per_m": round(PRESET_TENSION[preset] * tension_scale, 1),
        "stick_tip": rng.choice(STICK_TIPS),
        "grip": rng.choice(GRIPS),
        "humanize": humanize,
        "render_seed": rng.randrange(1, 2 ** 31),
        "split": split_of(seed, index),
    }
    return params, text, score.length_s


def from_file(seed, index, path):
    """An item from a given score file or MIDI drum part: the score as it is, the rest drawn."""
    params, _, _ = draw(seed, index)
    params.update(score_source=path, score_seed=0, meter="", hairpin="")
    return params
