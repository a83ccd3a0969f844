#!/usr/bin/env python3
"""A swing ride with its bell, as a new user writes it, through the real `ictusd render --kit
full` (docs/score.md, `on NAME-bell`; docs/midi.md, note 53):

- **typed**: four bars of the jazz ride ("ding, ding-a ding": quarter, triplet, quarter,
  triplet) in the right hand, the left foot's chick on 2 and 4, the kick feathered on 1, the
  left hand comping on the snare; the skip notes of the pattern on the ride's bell, drawn per
  seed (`on ride-bell`), and the pieces written in their common spellings (`on hi-hat`,
  `RF on bass-drum`); the tempo drawn in 110..170 bpm (seed 0: 140, where a bell
  aimed at the right hand's drum angle, 180 degrees, put the right palm 4 mm through the ride);
- **MIDI**: the same part as a Standard MIDI File, the bell as General MIDI's 53.

Asserted for each: every note one primary strike of its piece within 5 ms, every bell strike
on the bell (r/a <= 0.2) and every other ride strike on the bow (r/a >= 0.5), and no limb
through a piece (performance.bvh read by ictus_tools.limb_clearance).

    PYTHONPATH=python python3 tests/perform/test_ride_bell.py --ictusd build/ictusd [--seeds 0 1 2]
"""
import argparse
import os
import random
import subprocess
import tempfile

from ictus_tools import checks, e2e_util, limb_clearance
from ictus_tools.checks import check

TOL_MS = 5.0
TPQ = 480
BARS = 4


def part(seed):
    """(bpm, beats): each beat's (right-hand skip on the bell, left-hand comp on the triplet's
    last third, its dynamics) for BARS bars of 4/4."""
    rng = random.Random(seed)
    bpm = 140.0 if seed == 0 else float(rng.randint(110, 170))
    beats = []
    for b in range(4 * BARS):
        bell = b % 2 == 1 and (seed == 0 or rng.random() < 0.6)
        comp = rng.random() < 0.35
        beats.append((bell, comp, rng.choice(["pp", "p", "mp"])))
    return bpm, beats


def typed(bpm, beats):
    lines = ["tempo %g" % bpm]
    for b, (bell, comp, dyn) in enumerate(beats):
        foot = " + LF" if b % 2 == 1 else (" + RF on bass-drum pp" if b % 4 == 0 else "")
        if b % 2 == 0:
            lines.append("R on ride 1/1" + foot)
            continue
        lines.append("R on ride 2/3" + foot)
        skip = "R on %s 1/3" % ("ride-bell" if bell else "ride")
        lines.append(skip + (" + L on snare %s" % dyn if comp else ""))
    lines.append("R on ride 1/1 + RF on bass-drum mf")
    lines.append("L on hi-hat p 1/1 + R on ride")
    return "\n".join(lines) + "\n"


def midi_events(beats):
    dyn = {"pp": 30, "p": 45, "mp": 60}
    ev = []
    for b, (bell, comp, d) in enumerate(beats):
        t = b * TPQ
        ev.append((t, 51, 90))
        if b % 2 == 1:
            ev.append((t, 44, 70))
            skip = t + 2 * TPQ // 3
            ev.append((skip, 53 if bell else 51, 80))
            if comp:
                ev.append((skip, 38, dyn[d]))
        elif b % 4 == 0:
            ev.append((t, 36, 40))
    end = len(beats) * TPQ
    ev += [(end, 51, 90), (end, 36, 80), (end + TPQ, 51, 90), (end + TPQ, 42, 60)]
    return ev


def check_render(ictusd, work, name, source_args):
    out = os.path.join(work, name)
    run = subprocess.run([ictusd, "render", "--kit", "full"] + source_args +
                         ["--out", out, "--force"], capture_output=True, text=True,
                         timeout=900, env=e2e_util.pd_spawning_env(os.path.abspath(work)))
    check(run.returncode == 0, "%s: ictusd render exit %d %s" % (name, run.returncode,
                                                                 run.stderr[-1500:]))
    check("not struck" not in run.stderr, "%s: every note struck, by render's stderr %s"
          % (name, run.stderr.strip()[-600:]))
    _, names, rows, by_seq = e2e_util.read_kit_render(out)
    lost = [(r["line"], r["drum"], r["error_ms"]) for r in rows
            if not e2e_util.note_found(r, by_seq, names, TOL_MS)]
    worst = max(abs(float(r["error_ms"])) for r in rows if r["strike_seq"] != "-1")
    ride = names.index("ride")
    bell = [float(s["r_over_a"]) for s in by_seq.values() if s["drum"] == ride and
            s["bounce"] == 0 and float(s["r_over_a"]) < 0.35]
    bow = [float(s["r_over_a"]) for s in by_seq.values() if s["drum"] == ride and
           s["bounce"] == 0 and float(s["r_over_a"]) >= 0.35]
    c = limb_clearance.clearances(out)
    core = min(c.items(), key=lambda kv: kv[1].core_m)
    print("  %s: %d notes, worst error %.2f ms, bell r/a %s, bow r/a %.2f..%.2f; least core "
          "clearance %.1f mm (%s to %s at %.3f s)"
          % (name, len(rows), worst, ["%.2f" % r for r in sorted(set(bell))][:4] or "-",
             min(bow), max(bow), 1e3 * core[1].core_m, core[0][0], core[0][1],
             core[1].time_s))
    check(not lost, "%s: every note one primary strike of its piece within %g ms: lost %s"
          % (name, TOL_MS, lost[:6]))
    return bell, bow, core[1].core_m


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--ictusd", required=True)
    ap.add_argument("--workdir")
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    args = ap.parse_args()
    e2e_util.require_mido()
    work = args.workdir or tempfile.mkdtemp(prefix="ictus-bell-")
    os.makedirs(work, exist_ok=True)
    for seed in args.seeds:
        bpm, beats = part(seed)
        n_bell = sum(b[0] for b in beats)
        print("seed %d: %g bpm, %d bell notes" % (seed, bpm, n_bell))
        score = os.path.join(work, "bell-%d.txt" % seed)
        with open(score, "w") as f:
            f.write(typed(bpm, beats))
        mid = os.path.join(work, "bell-%d.mid" % seed)
        e2e_util.write_drum_midi(e2e_util.require_mido(), mid, midi_events(beats), bpm, TPQ)
        for name, src in (("typed-%d" % seed, ["--score", score]),
                          ("midi-%d" % seed, ["--midi", mid])):
            bell, bow, core = check_render(args.ictusd, work, name, src)
            check(len(bell) == n_bell and all(r <= 0.2 for r in bell),
                  "%s: each of the %d bell notes on the bell (r/a <= 0.2): %d, r/a %s"
                  % (name, n_bell, len(bell), sorted(bell)[-3:]))
            check(all(r >= 0.5 for r in bow), "%s: the other ride strikes on the bow (r/a >= "
                  "0.5): least %.2f" % (name, min(bow)))
            check(core > 0.0, "%s: no limb through a drum, a cymbal or a stand (its core "
                  "outside every piece): %.1f mm" % (name, 1e3 * core))
    return checks.finish()


if __name__ == "__main__":
    raise SystemExit(main())
