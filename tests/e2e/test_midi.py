"""`ictusd render` writes performance.mid (docs/midi.md): read here with an
independent reader (mido, Debian's python3-mido) and held against strikes.csv
of the same render, one note per strike, one to one in order:
- the file is a Standard MIDI File (type 0) with a tempo meta event at 0;
- note-on k is strike k: its time (mido's seconds, through the file's own tempo
  map, plus render.json's midi.tick0_time_s, the render time of tick 0) within
  1 ms of time_s, its channel the one asked for, its note
  48 + 4 hand + zone with the zone from r_over_a (centre < 0.25 <= middle <
  0.65 <= edge), its velocity 1 + 126 ln(v / 0.1) / ln(100) rounded into
  1..127 from normal_velocity_mps — computed here from the CSV;
- each note ends 0.1 s later or where the same note strikes again (within
  1 ms), and every bounce strike has a text event "bounce" at its tick;
- --midi-channel outside 1..16 is a usage error (exit 2) naming the option;
- on a DAW's grid: a score in 3/4 of 16ths at 100 bpm gives a 3/4 time
  signature at tick 0, a tempo of 600 000 us a quarter, its first note on a
  bar line and every note within 2 % of a beat of the 16th grid (in ticks,
  960 a 16th at mido's ticks_per_beat 3840, read from the file).
The score is tests/e2e/short.score (fast alternating hands, with bounces)."""
import argparse
import json
import os
import subprocess

from ictus_tools import e2e_util as u
from ictus_tools.checks import check
from ictus_tools.pdrun import make_workdir

mido = u.require_mido()

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
ap.add_argument("--score", required=True)
args = ap.parse_args()
ictusd = os.path.join(os.path.abspath(args.build), "ictusd")
work = make_workdir("ictus-midi-")
env = dict(os.environ)
env.pop("LD_PRELOAD", None)


def zone(r):
    return 0 if r < 0.25 else (1 if r < 0.65 else 2)


for channel in (1, 10):
    out = os.path.join(work, "ch%d" % channel)
    proc = subprocess.run([ictusd, "render", "--score", args.score, "--out", out,
                           "--midi-channel", str(channel), "--bvh-rate", "0", "--tips-rate", "0"],
                          capture_output=True, text=True, timeout=600, env=env)
    check(proc.returncode == 0, "ictusd render --midi-channel %d ran: %s" % (channel, proc.stderr[-2000:]))
    strikes = u.read_strikes(os.path.join(out, "strikes.csv"))
    check(len(strikes) >= 8, "the score gives strikes (%d)" % len(strikes))
    mid = mido.MidiFile(os.path.join(out, "performance.mid"))
    check(mid.type == 0 and len(mid.tracks) == 1, "performance.mid is a type 0 SMF with one track")
    with open(os.path.join(out, "render.json")) as f:
        t0 = json.load(f)["midi"]["tick0_time_s"]
    t, ons, offs, texts, tempos = t0, [], [], [], []
    for msg in mid:  # mido gives delta times in seconds, through the file's tempo map
        t += msg.time
        if msg.type == "set_tempo":
            tempos.append((t, msg.tempo))
        elif msg.type == "text":
            texts.append((t, msg.text))
        elif msg.type == "note_on" and msg.velocity > 0:
            ons.append((t, msg))
        elif msg.type == "note_off" or (msg.type == "note_on" and msg.velocity == 0):
            offs.append((t, msg))
    check(tempos and tempos[0][0] == t0, "a tempo meta event at time 0 (%s)" % tempos[:3])
    check(len(ons) == len(strikes), "one note per strike (%d notes, %d strikes)" % (len(ons), len(strikes)))
    worst = 0.0
    for k, ((tn, msg), s) in enumerate(zip(ons, strikes)):
        worst = max(worst, abs(tn - s["time_s"]))
        want_note = 48 + 4 * s["hand"] + zone(s["r_over_a"])
        want_vel = u.midi_velocities(s["normal_velocity_mps"])
        if not (abs(tn - s["time_s"]) <= 1e-3 and msg.channel == channel - 1 and
                msg.note == want_note and msg.velocity in want_vel):
            check(False, "note %d (%s at %.6f s) is strike %d (time %.6f, hand %d, r/a %.4f, "
                  "%.4f m/s: note %d velocity %s, channel %d)"
                  % (k, msg, tn, s["seq"], s["time_s"], s["hand"], s["r_over_a"],
                     s["normal_velocity_mps"], want_note, want_vel, channel - 1))
    print("notes vs strikes.csv: max |time difference| %.4f ms over %d notes" % (worst * 1e3, len(ons)))
    check(True, "every note is its strike: time within 1 ms, in order, note, velocity, channel")
    # lengths: each note-off is the next one of that note number after its note-on
    pending = {}
    events = sorted([(tn, 1, i) for i, (tn, _) in enumerate(ons)] +
                    [(tf, 0, i) for i, (tf, _) in enumerate(offs)])
    ends = [None] * len(ons)
    for tm, kind, i in events:
        if kind == 1:
            n = ons[i][1].note
            if n in pending:
                check(False, "note %d strikes again only after its note-off (%.6f)" % (n, tm))
            pending[n] = i
        else:
            n = offs[i][1].note
            if n not in pending:
                check(False, "a note-off (%d at %.6f) ends a sounding note" % (n, tm))
            ends[pending.pop(n)] = tm
    check(not pending and all(e is not None for e in ends), "every note ends")
    for k, s in enumerate(strikes):
        note = ons[k][1].note
        nxt = [s2["time_s"] for s2 in strikes[k + 1:]
               if 48 + 4 * s2["hand"] + zone(s2["r_over_a"]) == note]
        want = min(s["time_s"] + 0.1, nxt[0]) if nxt else s["time_s"] + 0.1
        if abs(ends[k] - want) > 1e-3:
            check(False, "note %d ends at %.6f, want %.6f (0.1 s or the next same note)" % (k, ends[k], want))
    check(True, "each note lasts 0.1 s or until its note number strikes again")
    bounce_times = [s["time_s"] for s in strikes if s["bounce"]]
    check([x for _, x in texts] == ["bounce"] * len(bounce_times) and
          all(abs(a - b) <= 1e-3 for (a, _), b in zip(texts, bounce_times)),
          "a text event 'bounce' with each of the %d bounces" % len(bounce_times))
    if not bounce_times:
        print("NOTE: this render has no bounces; the bounce flag is checked byte by byte in "
              "tests/cli/test_midi_file.cpp")


# On a DAW's grid: 3/4, 16ths at 100 bpm (two bars, both hands).
grid_score = os.path.join(work, "grid.score")
with open(grid_score, "w") as f:
    f.write("meter 3/4\ntempo 100\nbeats 1/4\nrepeat 12\nR\nL\nend\n")
out = os.path.join(work, "grid")
proc = subprocess.run([ictusd, "render", "--score", grid_score, "--out", out,
                       "--bvh-rate", "0", "--tips-rate", "0"],
                      capture_output=True, text=True, timeout=600, env=env)
check(proc.returncode == 0, "ictusd render of the 3/4 score ran: %s" % proc.stderr[-2000:])
mid = mido.MidiFile(os.path.join(out, "performance.mid"))
tpq = mid.ticks_per_beat
tick, ons, sigs, tempos = 0, [], [], []
for msg in mid.tracks[0]:
    tick += msg.time
    if msg.type == "time_signature":
        sigs.append((tick, msg.numerator, msg.denominator))
    elif msg.type == "set_tempo":
        tempos.append((tick, msg.tempo))
    elif msg.type == "note_on" and msg.velocity > 0:
        ons.append(tick)
check(sigs == [(0, 3, 4)], "one time signature, 3/4 at tick 0 (%s)" % sigs)
check(tempos == [(0, 600000)], "one tempo, 100 bpm at tick 0 (%s)" % tempos)
check(len(ons) >= 24, "the 24 notes are struck (%d notes)" % len(ons))
bar = 3 * tpq
off_bar = min(ons[0] % bar, bar - ons[0] % bar)
check(off_bar <= 0.02 * tpq, "the first note on a bar line (tick %d, %d off)" % (ons[0], off_bar))
sixteenth = tpq // 4
worst = max(min(n % sixteenth, sixteenth - n % sixteenth) for n in ons)
print("3/4 at 100 bpm: first note at tick %d (bar %d), worst distance to the 16th grid "
      "%d ticks = %.2f %% of a beat" % (ons[0], round(ons[0] / bar) + 1, worst, 100.0 * worst / tpq))
check(worst <= 0.02 * tpq, "every note within 2 %% of a beat of the 16th grid (worst %.2f %%)"
      % (100.0 * worst / tpq))

bad = subprocess.run([ictusd, "render", "--score", args.score, "--out", os.path.join(work, "bad"),
                      "--midi-channel", "17"], capture_output=True, text=True, timeout=60, env=env)
check(bad.returncode == 2 and "--midi-channel" in bad.stderr,
      "--midi-channel 17: exit 2 naming the option (%d: %s)" % (bad.returncode, bad.stderr.strip()))
print("PASS")
