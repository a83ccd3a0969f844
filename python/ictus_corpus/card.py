"""The dataset card: README.md in the corpus folder (what was drawn from what, counts, label
schema, licence)."""
import collections
import os
import subprocess

from ictus_corpus import params as P

SCHEMA = [
    ("sample", "int", "the strike's first sample in performance.wav: floor(time_s * 48000 + 0.5)"),
    ("time_s", "float", "onset time, s, from the start of the WAV (strikes.csv)"),
    ("hand", "str", "left | right"),
    ("drum", "int", "the drum's index in the kit, 0 without a kit"),
    ("zone", "str", "head | rim"),
    ("bounce", "bool", "a bounce (a second contact of the same stroke), not a stroke"),
    ("nuance", "str", "the score's nuance of the note this strike plays; null for a bounce"),
    ("dynamics", "float", "the note's dynamics 0..1 (hairpins applied); null for a bounce"),
    ("impact_speed_mps", "float", "normal tip speed just before contact, m/s"),
    ("tangential_speed_mps", "float", "in-plane tip speed just before contact, m/s"),
    ("peak_force_n", "float", "peak normal force, N"),
    ("impulse_n_s", "float", "normal impulse, N s"),
    ("contact_time_ms", "float", "onset to release, ms"),
    ("r_over_a", "float", "distance from the centre / the head's radius"),
    ("theta_deg", "float", "angle on the head, degrees"),
]


def _version(ictusd):
    try:
        return subprocess.run([ictusd, "--version"], stdout=subprocess.PIPE, text=True,
                              timeout=30).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return "unknown"


def _counts(rows, key):
    c = collections.Counter(str(r[key]) for r in rows if r["status"] != "failed")
    return ", ".join("%s %d" % kv for kv in sorted(c.items()))


def write(out, args, rows, ictusd):
    ok = [r for r in rows if r["status"] != "failed"]
    failed = [r for r in rows if r["status"] == "failed"]
    lines = [
        "# ictus corpus: seed %d, %d items" % (args.seed, len(rows)), "",
        "Simulated drum performances rendered by ictus (`ictusd render`, %s): a physically "
        "simulated percussionist plays a score on a simulated drum; each strike is detected on "
        "the simulated head and sounded by a modal membrane in Pd. Made with `ictus-corpus "
        "--count %d --seed %d%s` (docs/corpus.md in the ictus repository)."
        % (_version(ictusd), args.count, args.seed,
           " --from %s" % args.from_dir if args.from_dir else ""), "",
        "## Counts", "",
        "- items: %d finished, %d failed (their errors are in manifest.parquet)" % (
            len(ok), len(failed)),
        "- splits: %s" % _counts(rows, "split"),
        "- drum presets: %s" % _counts(rows, "drum_preset"),
        "- stick tips: %s" % _counts(rows, "stick_tip"),
        "- grips: %s" % _counts(rows, "grip"),
        "- meters: %s" % _counts(rows, "meter"),
        "", "## What was drawn from what", "",
        "Each item k draws from its own generator, seeded by (seed, k) alone: item k is the "
        "same whatever the count.",
        "",
        "- score: `ictus_tools.random_score` (the whole score language: rudiments, tempi "
        "40..220 bpm and ramps, rests, repeats, nuances, dynamics, strike spots `at R/A "
        "THETA`, both hands, grips) with a seed drawn uniformly in 1..2^31-1%s; a `meter` "
        "line drawn from %s (weights) and, with probability %.2f, a hairpin `dynamics A -> B "
        "over N` at beat 0 (A != B uniform over pp..ff, N uniform in %d..%d beats)"
        % (" (or the files of --from)" if args.from_dir else "",
           ", ".join("%d/%d: %d" % m for m in P.METERS), P.HAIRPIN_P, *P.HAIRPIN_BEATS),
        "- drum preset: uniform over %s; tension: the preset's (N/m: %s) times a factor "
        "log-uniform in %g..%g" % (", ".join(P.DRUM_PRESETS), ", ".join(
            "%s %g" % kv for kv in P.PRESET_TENSION.items()), *P.TENSION_SCALE),
        "- stick tip: uniform over %s; grip: uniform over %s" % (
            ", ".join(P.STICK_TIPS), ", ".join(P.GRIPS)),
        "- humanize: 0 with probability %.2f, else uniform in %g..%g; the noise seed uniform "
        "in 1..2^31-1" % (1 - P.HUMANIZE_P, *P.HUMANIZE_RANGE),
        "- split: train %.0f%% / validation %.0f%% / test %.0f%% by SHA-256 of (seed, k): an "
        "item keeps its split when the corpus grows" % tuple(100 * p for _, p in P.SPLITS),
        "", "## Files", "",
        "`item-NNNNNN/`: performance.wav (stereo, 48 kHz, 24-bit PCM), performance.mid, "
        "strikes.csv, notes.csv, events.txt, render.json, score.txt, labels.json%s, "
        "checksums.json (SHA-256 of each). `manifest.parquet`: one row per item (its "
        "parameters, files, checksums, status, error)." % (
            ", performance.bvh (the motion, 250 Hz)" if args.bvh else ""),
        "", "## Label schema", "",
        "labels.json: `item` (the parameters above), `sample_rate`, `wav_bits` and `onsets`, "
        "one per strike in time order:", "",
        "| field | type | meaning |", "|---|---|---|",
    ]
    lines += ["| %s | %s | %s |" % s for s in SCHEMA]
    lines += ["", "## Licence", "",
              "The corpus is made by ictus and is under ictus's licence, BSD-3-Clause. The "
              "performer plays from ictus's built-in gesture database, a parametric stroke "
              "model (docs/gestures.md), not motion capture: no third-party data is in it.",
              ""]
    with open(os.path.join(out, ".tmp", "README.md"), "w") as f:
        f.write("\n".join(lines))
    os.replace(os.path.join(out, ".tmp", "README.md"), os.path.join(out, "README.md"))
