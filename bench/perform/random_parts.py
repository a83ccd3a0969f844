#!/usr/bin/env python3
"""How far the whole kit's drummer plays drum parts it was not built on: seeded parts of 8 bars,
written as a new user's DAW would write them (General MIDI, channel 10, mido), rendered with
`ictusd render --kit full --midi` and scored as tests/perform/test_song.py scores its song (a
note found when its strike is primary, on its drum, of its limb, within +-5 ms; F1 over primary
strikes and notes). A measurement, not a test: what it prints is in docs/midi.md, "Beyond the
song".

Each part draws its tempo (80-140 bpm), the time-keeper's subdivision (8ths, or 16ths with one
hand), ghost notes on the snare's 16ths, the backbeat as a side stick, the hi-hat or the ride
bar by bar (an open hi-hat on a bar's last subdivision), the kick on 1 and 3, the hi-hat's pedal
on 2 and 4 under the ride, and in bars 4 and 8 a fill over beats 3-4 (16ths or triplets, a
random walk over the toms and the snare) into a crash with the kick on the next downbeat.

    PYTHONPATH=python python3 bench/perform/random_parts.py --ictusd build/ictusd --seeds 1-20
"""
import argparse
import os
import random
import subprocess
import sys
import tempfile

from ictus_tools import e2e_util
from ictus_tools import limb_clearance

TOL_MS = 5.0
TPQ = 480
TOMS = [48, 47, 43, 50, 45, 41, 38]


def part(seed):
    """(notes as (tick, note, velocity), bpm, description) of the part of `seed`."""
    r = random.Random(seed)
    bpm = r.choice([80, 90, 100, 110, 120, 130, 140])
    sub = r.choice([2, 2, 4])
    ghost = sub == 2 and r.random() < 0.4
    side = r.random() < 0.25
    notes = []
    for b in range(8):
        o = b * 4 * TPQ
        keeper = 51 if b >= 4 and r.random() < 0.5 else 42
        fill = b in (3, 7)
        for i in range(4 * sub):
            t, beat = o + i * TPQ // sub, i // sub
            if fill and beat >= 2:
                break
            open_hat = keeper == 42 and i == 4 * sub - 1 and r.random() < 0.3
            notes.append((t, 46 if open_hat else keeper, r.randint(60, 100)))
            if i % sub == 0 and beat in (1, 3):
                notes.append((t, 37 if side else 38, r.randint(85, 115)))
                if keeper == 51:
                    notes.append((t, 44, 70))
            if i % sub == 0 and beat in (0, 2):
                notes.append((t, 36, 100))
            if ghost and i % 2 == 1 and r.random() < 0.3:
                notes.append((t, 38, r.randint(20, 40)))
        if fill:
            per_beat = r.choice([4, 4, 3])
            cur = r.randrange(len(TOMS))
            for k in range(2 * per_beat):
                if r.random() < 0.4:
                    cur = min(len(TOMS) - 1, max(0, cur + r.choice([-1, 1, 1])))
                notes.append((o + 2 * TPQ + k * TPQ // per_beat, TOMS[cur], r.randint(80, 120)))
            notes.append((o + 4 * TPQ, 49, 120))
            notes.append((o + 4 * TPQ, 36, 110))
    what = "%d bpm, %s%s%s" % (bpm, "16ths" if sub == 4 else "8ths", ", ghosts" if ghost else "",
                               ", side stick" if side else "")
    return notes, bpm, what


def score(out):
    """(F1, worst error ms, [missed notes], shell passes, least limb core clearance mm)."""
    rj, names, notes, by_seq = e2e_util.read_kit_render(out)
    primary = sum(1 for s in by_seq.values() if s["bounce"] == 0)
    found, worst, missed = 0, 0.0, []
    for n in notes:
        if e2e_util.note_found(n, by_seq, names, TOL_MS):
            found += 1
            worst = max(worst, abs(float(n["error_ms"])))
        else:
            missed.append("%s %s %.2f s%s" % (n["hand"], n["drum"], float(n["time_s"]),
                                              " (%+.0f ms)" % float(n["error_ms"])
                                              if n["error_ms"] else ""))
    p, r = found / max(primary, 1), found / max(len(notes), 1)
    f1 = 2 * p * r / (p + r) if found else 0.0
    core = min(c.core_m for c in limb_clearance.clearances(out).values())
    return f1, worst, missed, rj["kit"].get("shell_passes"), 1e3 * core


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ictusd", required=True)
    ap.add_argument("--seeds", type=e2e_util.seed_range, default=e2e_util.seed_range("1-20"))
    ap.add_argument("--workdir", default=None)
    a = ap.parse_args()
    mido = e2e_util.require_mido()
    work = a.workdir or tempfile.mkdtemp(prefix="ictus-random-parts-")
    os.makedirs(work, exist_ok=True)
    perfect, f1s = 0, []
    print("| seed | part | notes | F1 | worst ms | stick passes | limb core mm | not found |")
    print("|---|---|---|---|---|---|---|---|")
    for seed in a.seeds:
        notes, bpm, what = part(seed)
        path = os.path.join(work, "part%d.mid" % seed)
        e2e_util.write_drum_midi(mido, path, notes, bpm, TPQ)
        out = os.path.join(work, "part%d" % seed)
        run = subprocess.run([a.ictusd, "render", "--kit", "full", "--midi", path, "--out", out,
                              "--force"], capture_output=True, text=True, timeout=900)
        if run.returncode != 0:
            print("| %d | %s | render failed: %s |" % (seed, what, run.stderr[-300:]))
            continue
        f1, worst, missed, passes, core = score(out)
        perfect += f1 == 1.0
        f1s.append(f1)
        print("| %d | %s | %d | %.3f | %.2f | %s | %.1f | %s |"
              % (seed, what, len(notes), f1, worst, passes, core, "; ".join(missed[:4])
                 + (" ..." if len(missed) > 4 else "")))
    print("\n%d of %d parts at F1 1.000; mean F1 %.3f" % (perfect, len(f1s),
                                                        sum(f1s) / max(len(f1s), 1)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
