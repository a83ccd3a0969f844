#!/usr/bin/env python3
"""Five passages of a drum part that ask more than the hands can do in time, and what the
drummer does with them (docs/midi.md, "Beyond the song"), through the real `ictusd render
--kit full --midi` of parts written here (mido, 140 bpm unless said, 480 ticks a quarter):

- **the time-keeper changes cymbal without a rest**: a bar of 16th notes on the ride, then
  two on the hi-hat (the snare on 2 and 4, the kick on 1 and 3). The right hand has one 16th,
  107 ms, to cross from the ride to the hi-hat, about a metre: it cannot, and the left hand
  keeps the hi-hat going (docs/midi.md) until the right has crossed. Asserted: the right hand
  strikes the hi-hat on time (within 5 ms) within a beat (0.43 s) of the change, the notes
  before that are the left's, and every note is found. (Before the left took them, the
  right's first hi-hat notes were lost; a shoulder held by its range's stop at every step,
  its target across the stop, froze for 1.3 s: ten notes lost.)
- **a fill into a crash alone**: two bars of 8th-note hi-hat and backbeat, a third that stops
  on beat 2, then after a beat's rest two beats of 16ths on tom1 and tom2 into a crash with
  the kick on the next downbeat. Begun on the right (the lead, after the rest), the run would
  leave the left hand one 16th (107 ms) to cross from tom2 to the crash, 0.84 m; the
  sticking starts it on the left (docs/midi.md), so the right plays the last 16th and the
  left has two. Asserted: every note found within 5 ms, the crash by the left hand, the
  fill begun on the left and ended on the right.
- **a ghost note into a fill** (99 bpm): a bar of 8th-note hi-hat and backbeat, a ghost snare
  a 16th after the last hi-hat, a fill of 16ths (snare, tom1, tom2, floor tom, two each) into a
  crash with the kick. Singles from the ghost on would end the fill on the left, a 16th from
  the crash; turned whole, the ghost was the right's, from the hi-hat in a 16th, 30 ms early.
  The sticking gives the ghost to the left and ends the fill on a double of the right on the
  floor tom (docs/midi.md). Asserted: every note found within 5 ms, the ghost the left's.
- **a fill into a crash with the hi-hat going on**, seeded: a bar of the groove at 100-130 bpm,
  then two beats of 16ths wandering over the toms and ending on the snare or tom1, the crash
  and the kick on the downbeat, and a bar of 8th-note hi-hat. On the downbeat both hands would
  cross the kit in one 16th (the left to the crash, the right over it to the hi-hat, 107-150
  ms): where the right's move is over 3.5 m/s the hi-hat is the left foot's chick, and the
  left's lift over the hi-hat peaks where the hi-hat is (docs/kit.md, "Playing it").
  Asserted: every note found within 5 ms, the downbeat's two too (without the chick seeds 5-8
  lost the hi-hat: two not struck, two 32-37 ms early; with the lift peaking mid-move the
  crash was 9-31 ms off on the same seeds; a right stick wedged on the hi-hat's rim once lost
  the whole bar after it), and no limb through the hi-hat's rod (the
  left palm swept through it on its way to the crash).
- **a song's crossings**: 16 bars at 140 bpm of 8th-note hi-hat (the ride in bars 9-12, an
  open hi-hat ending bars 2, 6 and 14), the snare on 2 and 4, and in every fourth bar a
  fill of 16ths down the toms to the floor tom into a crash with the kick and the time-keeper
  on the next downbeat. The right hand crosses from the floor tom to the hi-hat or the ride
  again and again. Asserted: no hand loses two of its notes in a row (the arm's solve, warm
  from its last one, once stayed folded across the chest, 16-18 cm short of the hi-hat, and
  the right hand lost 28 notes in a row; docs/ik.md).

    PYTHONPATH=python python3 tests/perform/test_recover.py --ictusd build/ictusd [--workdir DIR] \
        [--fill-seeds 1 2 ...]
"""
import argparse
import os
import random
import subprocess
import tempfile

from ictus_tools import checks, e2e_util, limb_clearance
from ictus_tools.checks import check

BPM, TPQ = 140.0, 480
TOL_MS = 5.0


def render(ictusd, work, name, notes, bpm=BPM, bvh=False):
    """notes.csv's rows, each with its strike (None when not struck), of the part `notes`."""
    mido = e2e_util.require_mido()
    path = os.path.join(work, name + ".mid")
    e2e_util.write_drum_midi(mido, path, notes, bpm, TPQ)
    out = os.path.join(work, name)
    run = subprocess.run([ictusd, "render", "--kit", "full", "--midi", path, "--out", out,
                          "--force"] + ([] if bvh else ["--bvh-rate", "0"]),
                         capture_output=True, text=True,
                         timeout=900, env=e2e_util.pd_spawning_env(os.path.abspath(work)))
    check(run.returncode == 0, "%s: ictusd render exit %d %s" % (name, run.returncode,
                                                                 run.stderr[-1500:]))
    _, names, rows, by_seq = e2e_util.read_kit_render(out)
    for r in rows:
        r["found"] = e2e_util.note_found(r, by_seq, names, TOL_MS)
        r["t"] = float(r["time_s"])
    return rows


def found(r):
    """The note got one primary strike on its piece within TOL_MS."""
    return r["found"]


def cymbal_change(ictusd, work):
    e16 = TPQ // 4
    notes = []
    for b in range(3):
        keeper = 51 if b == 0 else 42
        for i in range(16):
            notes.append((b * 16 * e16 + i * e16, keeper, 80))
        for beat in range(4):
            notes.append((b * 4 * TPQ + beat * TPQ, 38 if beat % 2 else 36, 100))
    rows = render(ictusd, work, "cymbal-change", notes)
    change = min(r["t"] for r in rows if r["drum"] == "hihat")
    hats = [r for r in rows if r["drum"] == "hihat"]
    back = next((r for r in hats if r["hand"] == "right" and found(r)), None)
    late = back["t"] - change if back else float("inf")
    lost = [r for r in hats if not found(r)]
    print("cymbal change: the hi-hat from %.3f s; the right hand on it %.3f s later; %d of %d "
          "hi-hat notes lost" % (change, late, len(lost), len(hats)))
    check(late <= 60.0 / BPM, "the right hand strikes the hi-hat on time within a beat (%.2f s) "
          "of the change: %.3f s" % (60.0 / BPM, late))
    check(back is not None and all(r["hand"] == "left" for r in hats if r["t"] < back["t"]),
          "the hi-hat notes before the right's are the left hand's: %s"
          % [(r["t"], r["hand"]) for r in hats if back and r["t"] < back["t"]])
    others = [r for r in rows if not found(r)]
    check(not others, "every note found within 5 ms: %s"
          % [(r["t"], r["drum"], r["hand"], r["error_ms"]) for r in others])


def fill_into_crash(ictusd, work):
    e8, e16 = TPQ // 2, TPQ // 4
    notes = []
    for b in range(3):  # the third bar stops after beat 2: a beat's rest before the fill
        for i in range(8 if b < 2 else 3):
            notes.append((b * 8 * e8 + i * e8, 42, 80))
        for beat in range(4 if b < 2 else 2):
            notes.append((b * 4 * TPQ + beat * TPQ, 38 if beat % 2 else 36, 100))
    fill = [48, 48, 48, 48, 47, 47, 47, 47]
    notes += [(10 * TPQ + k * e16, tom, 105) for k, tom in enumerate(fill)]
    notes += [(12 * TPQ, 49, 120), (12 * TPQ, 36, 110)]
    rows = render(ictusd, work, "fill-into-crash", notes)
    lost = [(r["t"], r["drum"], r["hand"], r["error_ms"]) for r in rows if not found(r)]
    crash = [r for r in rows if r["drum"] == "crash"]
    fill_rows = sorted((r for r in rows if r["drum"] in ("tom1", "tom2", "floor")),
                       key=lambda r: r["t"])
    worst = max(abs(float(r["error_ms"])) for r in rows if found(r))
    print("fill into a crash: %d notes, %d not found, worst %.2f ms; the fill's hands %s, the "
          "crash's %s" % (len(rows), len(lost), worst, "".join(r["hand"][0].upper()
                                                              for r in fill_rows),
                          [r["hand"] for r in crash]))
    check(not lost, "every note found within 5 ms: %s" % lost)
    check([r["hand"] for r in crash] == ["left"] and fill_rows[-1]["hand"] == "right"
          and fill_rows[0]["hand"] == "left",
          "the fill begun on the left and ended on the right, the crash by the left")


def ghost_into_fill(ictusd, work):
    """A new user's groove at 99 bpm: hi-hat 8ths, a ghost snare a 16th after the last one,
    a fill of 16ths 38 38 48 48 47 47 43 43 into a crash with the kick."""
    e8, e16 = TPQ // 2, TPQ // 4
    notes = []
    for i in range(8):
        notes.append((i * e8, 42, 80))
        if i in (0, 4):
            notes.append((i * e8, 36, 100))
        if i in (2, 6):
            notes.append((i * e8, 38, 100))
    notes.append((7 * e8 + e16, 38, 21))
    fill = [38, 38, 48, 48, 47, 47, 43, 43]
    notes += [(4 * TPQ + k * e16, tom, 100) for k, tom in enumerate(fill)]
    notes += [(6 * TPQ, 49, 120), (6 * TPQ, 36, 110)]
    rows = render(ictusd, work, "ghost-into-fill", notes, bpm=99.0)
    ghost = [r for r in rows if r["drum"] == "snare" and abs(r["t"] - (1.0 + 3.75 * 60 / 99.0))
             < 1e-4]
    lost = [(r["t"], r["drum"], r["hand"], r["error_ms"]) for r in rows if not found(r)]
    print("ghost into a fill: %d notes, the ghost's hand %s" % (len(rows),
                                                                [r["hand"] for r in ghost]))
    check(not lost, "every note found within 5 ms (the ghost was the right's, from the hi-hat "
          "in a 16th, 30 ms early): %s" % lost)
    check([r["hand"] for r in ghost] == ["left"], "the ghost the left's")


def fill_hihat_on(ictusd, work, seeds=range(1, 9)):
    e8, e16 = TPQ // 2, TPQ // 4
    for seed in seeds:
        rng = random.Random(seed)
        bpm = rng.choice([100, 110, 120, 130])
        notes = []
        for i in range(12):  # a bar of the groove and the half bar before the fill
            notes.append((i * e8, 42, 80))
            if i % 2 == 0:
                notes.append((i * e8, 38 if (i // 2) % 2 else 36, 90))
        toms, cur, end = [48, 45, 43], rng.randrange(3), rng.choice([2, 4])
        last = rng.choice([38, 48])
        for k in range(8):
            if k < 8 - end and rng.random() < 0.4:
                cur = min(2, max(0, cur + rng.choice([-1, 1])))
            notes.append((6 * TPQ + k * e16, toms[cur] if k < 8 - end else last, 100))
        down = 8 * TPQ
        notes += [(down, 49, 120), (down, 36, 110)]
        notes += [(down + i * e8, 42, 80) for i in range(8)]
        rows = render(ictusd, work, "fill-hihat-on-%d" % seed, notes, bpm, bvh=True)
        lost = [(r["t"], r["drum"], r["hand"], r["error_ms"]) for r in rows if not found(r)]
        rod = limb_clearance.clearances(os.path.join(work, "fill-hihat-on-%d" % seed))
        rod_core = min(c.core_m for (limb, piece), c in rod.items() if piece == "hihat stand")
        print("fill into a crash, the hi-hat on (seed %d, %d bpm, ending on %s): %d notes, "
              "lost %s; least limb core clearance to the hi-hat's rod %.1f mm"
              % (seed, bpm, "the snare" if last == 38 else "tom1", len(rows), lost,
                 1e3 * rod_core))
        check(not lost, "seed %d: every note found within 5 ms, the downbeat's crash and hi-hat "
              "too (the hi-hat the left foot's chick when the right hand cannot reach it): %s"
              % (seed, lost))
        check(rod_core >= 0.0, "seed %d: no limb through the hi-hat's rod: %.1f mm"
              % (seed, 1e3 * rod_core))


def song_crossings(ictusd, work):
    e8, e16 = TPQ // 2, TPQ // 4
    notes = []
    for b in range(16):
        o, ride, fill = b * 4 * TPQ, 8 <= b < 12, b % 4 == 3
        for i in range(4 if fill else 8):
            if b % 4 or b == 0 or i:  # the downbeat after a fill: below
                notes.append((o + i * e8, 51 if ride else 46 if b % 4 == 1 and i == 7 else 42,
                              90 if i % 2 == 0 else 70))
            if i % 2 == 0:
                notes.append((o + i * e8, 38 if (i // 2) % 2 else 36, 105))
            if i == 5 and b % 2:
                notes.append((o + i * e8, 36, 90))
        if fill:
            notes += [(o + 2 * TPQ + k * e16, tom, 105)
                      for k, tom in enumerate([48, 48, 47, 47, 45, 45, 41, 41])]
        if b % 4 == 0 and b:
            notes += [(o, 49, 120), (o, 51 if ride else 42, 90)]
    notes += [(16 * 4 * TPQ, 49, 120), (16 * 4 * TPQ, 36, 110)]
    rows = render(ictusd, work, "song-crossings", notes)
    runs = {}
    for hand in ("left", "right"):
        run = 0
        for r in sorted((r for r in rows if r["hand"] == hand), key=lambda r: r["t"]):
            run = 0 if found(r) else run + 1
            runs[hand] = max(runs.get(hand, 0), run)
    lost = [(r["t"], r["drum"], r["hand"]) for r in rows if not found(r)]
    print("a song's crossings: %d notes, %d lost %s; the longest run of a hand's notes lost: "
          "left %d, right %d" % (len(rows), len(lost), lost[:8], runs["left"], runs["right"]))
    check(max(runs.values()) <= 1, "no hand loses two of its notes in a row: %s" % runs)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ictusd", required=True)
    ap.add_argument("--workdir", default=None)
    ap.add_argument("--fill-seeds", type=int, nargs="+", default=list(range(1, 9)),
                    help="the seeds of the fills into a crash with the hi-hat on (default 1-8)")
    a = ap.parse_args()
    work = a.workdir or tempfile.mkdtemp(prefix="ictus-recover-")
    os.makedirs(work, exist_ok=True)
    checks.keep_going()  # every passage is reported
    cymbal_change(a.ictusd, work)
    fill_into_crash(a.ictusd, work)
    ghost_into_fill(a.ictusd, work)
    fill_hihat_on(a.ictusd, work, a.fill_seeds)
    song_crossings(a.ictusd, work)
    checks.finish()


if __name__ == "__main__":
    main()
