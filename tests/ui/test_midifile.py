"""[ictus-midifile] (patches/ictus-midifile.pd, docs/midi.md "A MIDI file in the main
patch"), in the real pd (batch): a Standard MIDI File written here with mido (a drum part on
channel 10, a tempo change, notes the map leaves out, a note-off as a velocity-0 note-on, a
note on another channel) is played through cyclone's [seq]. Every note-on of channel 10 must
come out once, in order, as "note N V G" at its time in the file (mido's seconds, the tempo map
applied) within 1 ms of Pd's logical time: G the file's note (General MIDI, played with a kit),
N from the documented hand-and-zone map computed here for a snare or a tom (snare zone middle,
tom zone centre, the other hand when less than 300 ms after the previous snare or tom, else the
right hand), else 0 (kick, hi-hat: played only with a kit), those counted; the file's end
banged. A missing file gives the error line and no note."""
import argparse
import os
import shutil
import subprocess
import tempfile

from ictus_tools import uitest
from ictus_tools.checks import check

try:
    import mido
except ImportError:
    uitest.skip_or_fail("python3-mido is missing (scripts/deps.sh installs it)", missing_package=True)

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
build = os.path.abspath(args.build)

SNARES, TOMS = (38, 40), (41, 43, 45, 47, 48, 50)
TPQ = 480
# (beat, note, velocity, channel 1..16): channel 10 is the drum part.
EVENTS = [(0.0, 38, 100, 10), (0.0, 36, 90, 10), (0.5, 42, 60, 10), (1.0, 40, 64, 10),
          (1.25, 45, 127, 10), (1.5, 43, 30, 10), (2.0, 38, 0, 10), (2.0, 38, 80, 1),
          (3.0, 50, 70, 10), (5.0, 41, 110, 10), (5.125, 47, 90, 10), (6.0, 48, 1, 10)]


def write_smf(path):
    """Type 1: a tempo track (120 bpm, 90 bpm from beat 4) and the drum track."""
    f = mido.MidiFile(type=1, ticks_per_beat=TPQ)
    tempo = mido.MidiTrack()
    tempo.append(mido.MetaMessage("set_tempo", tempo=mido.bpm2tempo(120), time=0))
    tempo.append(mido.MetaMessage("set_tempo", tempo=mido.bpm2tempo(90), time=4 * TPQ))
    drums = mido.MidiTrack()
    now = 0
    timeline = []
    for beat, note, vel, ch in EVENTS:
        tick = int(round(beat * TPQ))
        timeline.append((tick, mido.Message("note_on", note=note, velocity=vel, channel=ch - 1)))
        timeline.append((tick + 60, mido.Message("note_off", note=note, velocity=0, channel=ch - 1)))
    for tick, msg in sorted(timeline, key=lambda e: (e[0], e[1].type == "note_on")):
        drums.append(msg.copy(time=tick - now))
        now = tick
    f.tracks += [tempo, drums]
    f.save(path)


def expected(path):
    """The notes the player must give, from mido's reading of the file: (time ms, N, V, G)."""
    out, t, last, hand = [], 0.0, None, 1
    for msg in mido.MidiFile(path):
        t += msg.time
        if msg.type != "note_on" or msg.velocity == 0 or msg.channel != 9:
            continue
        if msg.note not in SNARES + TOMS:
            out.append((t * 1000.0, 0, msg.velocity, msg.note))
            continue
        hand = 1 - hand if last is not None and (t - last) * 1000.0 < 300.0 else 1
        last = t
        zone = 1 if msg.note in SNARES else 0
        out.append((t * 1000.0, 48 + 4 * hand + zone, msg.velocity, msg.note))
    return out


def run(patch_text, work, name):
    patch = os.path.join(work, name)
    with open(patch, "w") as f:
        f.write(patch_text)
    proc = subprocess.run(uitest.PD_BATCH + ["-nomidi", "-path", os.path.join(build, "ictus"),
                                             "-open", patch],
                          capture_output=True, text=True, timeout=120, env=uitest.PD_ENV)
    return proc.stdout + proc.stderr


def patch_for(midi_file, channel):
    # play; each note with the logical ms since the play; at the end (outlet 2) quit.
    return ("#N canvas 0 0 500 400 12;\n"
            "#X obj 10 10 loadbang;\n"                          # 0
            "#X obj 10 40 t b b;\n"                             # 1
            "#X msg 10 70 open %s \\, play;\n"                  # 2
            "#X obj 10 100 ictus-midifile %d;\n"                # 3
            "#X obj 10 130 t a b;\n"                            # 4
            "#X obj 200 130 timer;\n"                           # 5
            "#X obj 10 190 list append;\n"                      # 6
            "#X obj 10 220 print got;\n"                        # 7
            "#X obj 200 100 print end;\n"                       # 8
            "#X obj 300 160 delay 100;\n"                       # 9
            "#X msg 300 190 \\; pd quit;\n"                     # 10
            "#X obj 380 10 delay 60000;\n"                      # 11
            "#X connect 0 0 1 0;\n#X connect 1 1 5 0;\n#X connect 1 0 2 0;\n"
            "#X connect 2 0 3 0;\n#X connect 3 0 4 0;\n#X connect 4 1 5 1;\n"
            "#X connect 5 0 6 1;\n#X connect 4 0 6 0;\n#X connect 6 0 7 0;\n"
            "#X connect 3 1 8 0;\n#X connect 3 1 9 0;\n#X connect 9 0 10 0;\n"
            "#X connect 0 0 11 0;\n#X connect 11 0 10 0;\n" % (midi_file, channel))


def check_plays(log, want):
    errors = [l for l in uitest.error_lines(log)]
    check(not errors, "no error lines: %s" % errors)
    got = []
    for line in log.splitlines():
        if line.startswith("got: "):
            words = [w for w in line[5:].split() if w != "list"]
            check(words[0] == "note", "a note message: %r" % line)
            got.append((float(words[4]), int(float(words[1])), int(float(words[2])),
                        int(float(words[3]))))
    print("file:", want)
    print("pd:  ", got)
    check(len(got) == len(want), "one note per note-on of channel 10 (%d, want %d)"
          % (len(got), len(want)))
    worst = max((abs(g[0] - w[0]) for g, w in zip(got, want)), default=0.0)
    check(all(abs(g[0] - w[0]) <= 1.0 for g, w in zip(got, want)),
          "each at its time in the file within 1 ms (worst %.3f ms)" % worst)
    check([g[1:] for g in got] == [w[1:] for w in want],
          "notes, velocities and GM notes as the documented map gives them: %s"
          % [g[1:] for g in got])
    left_out = sum(1 for _, n, v, ch in EVENTS if ch == 10 and v > 0 and n not in SNARES + TOMS)
    check(any(l.startswith("ictus-midifile: notes with no hand-and-zone note") and
              l.split()[-1] == str(left_out) for l in log.splitlines()),
          "the %d notes that only a kit plays are counted at the end" % left_out)
    check(any(l.startswith("end: bang") for l in log.splitlines()), "the end of the file is banged")


with tempfile.TemporaryDirectory(prefix="ictus-ui-midifile-") as work:
    smf = os.path.join(work, "part.mid")
    write_smf(smf)
    want = expected(smf)
    for name, patch_name in ((smf, "play.pd"), ("part.mid", "relative.pd"),
                             ("songs/part.mid", "relative-sub.pd")):
        # Absolute, then relative to the patch that holds [ictus-midifile] (not to the
        # abstraction's own folder, which is the build's).
        if name == "songs/part.mid":
            os.makedirs(os.path.join(work, "songs"), exist_ok=True)
            shutil.copy(smf, os.path.join(work, name))
        print("open %s from %s" % (name, patch_name))
        check_plays(run(patch_for(name, 10), work, patch_name), want)
    # A missing file: the error, and nothing plays.
    for name in (os.path.join(work, "missing.mid"), "missing.mid"):
        log = run(patch_for(name, 10), work, "missing.pd")
        check(any("error: ictus-midifile: no MIDI file" in l and name in l
                  for l in log.splitlines()), "a missing file is named in an error line: %s"
              % log[-500:])
        check(not any(l.startswith("got: ") for l in log.splitlines()), "and no note comes out")
print("PASS")
