"""[ictus-midi], the main patch's MIDI out (docs/midi.md), in the real pd (batch):
the strikes of a real render (`ictusd render` of tests/e2e/short.score, with
--midi-channel 3) go into the panel as the strike lists ictus-receive gives
(hand, velocity, r/a, theta, stick mass, peak force, bounce); the notes it sends must be,
one for one and in order, those of the render's performance.mid read with mido
(the same mapping live and offline), and those of the mapping computed here
from strikes.csv. Then: a bounce is played while 'bounces' is ticked and left
out when not; nothing comes out while 'on' is off; the channel is the one set. MIDI in
('in' ticked): a note of the mapping gives a strike list that maps back to it."""
import argparse
import math
import os
import subprocess
import tempfile

from ictus_tools import uitest
from ictus_tools.checks import check

from ictus_tools import e2e_util as u

try:
    import mido
except ImportError:
    uitest.skip_or_fail("python3-mido is missing (scripts/deps.sh installs it)", missing_package=True)

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
ap.add_argument("--ictusd", required=True)
args = ap.parse_args()
build = os.path.abspath(args.build)


# MIDI in: notes of the mapping and two that are not (51: no zone; velocity 0: a note-off)
MIDI_IN = [(48, 1), (49, 104), (50, 64), (52, 127), (53, 90), (54, 30), (51, 100), (53, 0)]


def mapping(hand, v, r):
    zone = 0 if r < 0.25 else (1 if r < 0.65 else 2)
    vel = 1 if not v > 0.1 else int(min(127, max(1, math.floor(1 + 126 * math.log(v / 0.1) / math.log(100) + 0.5))))
    return 48 + 4 * (hand != 0) + zone, vel


with tempfile.TemporaryDirectory(prefix="ictus-ui-midi-") as work:
    out = os.path.join(work, "out")
    env = dict(os.environ)
    env.pop("LD_PRELOAD", None)
    proc = subprocess.run([args.ictusd, "render", "--score", os.path.join(uitest.REPO, "tests", "e2e",
                                                                           "short.score"),
                           "--out", out, "--midi-channel", "3", "--bvh-rate", "0", "--tips-rate", "0"],
                          capture_output=True, text=True, timeout=600, env=env)
    check(proc.returncode == 0, "ictusd render ran: %s" % proc.stderr[-1000:])
    strikes = u.read_strikes(os.path.join(out, "strikes.csv"))
    file_notes = [(m.note, m.velocity, m.channel + 1) for m in mido.MidiFile(os.path.join(out, "performance.mid"))
                  if m.type == "note_on" and m.velocity > 0]
    lists = ["%d %.4f %.5f %.2f %.4f %.3f %d" % (s["hand"], s["normal_velocity_mps"], s["r_over_a"],
                                                 s["theta_deg"], s["stick_mass_kg"], s["peak_force_n"],
                                                 s["bounce"]) for s in strikes]
    msgs = (["on 1", "channel 3"] + lists +
            ["1 2 0.7 0 0.04 10 1", "bounces 0", "1 2 0.7 0 0.04 10 1", "bounces 1", "on 0", "0 5 0.5 0",
             "on 1", "channel 16", "0 5 0.5 0"] +
            ["note 49 104", "in 1"] + ["note %d %d" % nv for nv in MIDI_IN] + ["in 0", "note 52 100"])
    patch = os.path.join(work, "midi.pd")
    with open(patch, "w") as f:
        f.write("#N canvas 0 0 400 300 12;\n#X obj 10 10 loadbang;\n#X msg 10 40 %s;\n"
                "#X obj 10 70 ictus-midi;\n#X obj 10 260 print midi;\n#X obj 200 260 print midiin;\n"
                "#X connect 0 0 1 0;\n#X connect 1 0 2 0;\n#X connect 2 0 3 0;\n#X connect 2 1 4 0;\n"
                % " \\, ".join(msgs))
    proc = subprocess.run(uitest.PD_BATCH + ["-nomidi", "-path", os.path.join(build, "ictus"),
                                             "-open", patch, "-send", "pd quit"],
                          capture_output=True, text=True, timeout=60, env=uitest.PD_ENV)
log = proc.stdout + proc.stderr
check(not uitest.error_lines(log), "no error lines: %s" % uitest.error_lines(log))
got = [tuple(int(float(w)) for w in l.split()[1:]) for l in log.splitlines() if l.startswith("midi: ")]
n = len(strikes)
check(len(file_notes) == n and len(got) == n + 2,
      "a note per strike (%d strikes, %d in performance.mid, %d from the panel, +2 expected after)"
      % (n, len(file_notes), len(got)))
live = [(g[0], g[1], g[2]) for g in got[:n]]
check(live == file_notes, "the panel's notes are performance.mid's, in order (note, velocity, channel)")
check(live == [mapping(s["hand"], s["normal_velocity_mps"], s["r_over_a"]) + (3,) for s in strikes],
      "... and the mapping computed here from strikes.csv")
check([g[3] for g in got[:n]] == [s["bounce"] for s in strikes], "the outlet flags the bounces")
check(got[n] == (54, 83, 3, 1), "a bounce plays while 'bounces' is ticked: %s" % (got[n],))
check(got[n + 1] == (48 + 1, mapping(0, 5, 0.5)[1], 16, 0),
      "nothing while off; then on channel 16: %s (the bounce with 'bounces' off left out)" % (got[n + 1],))
# MIDI in: each note-on of the mapping gives a strike list whose hand, zone and speed map
# back (with the mapping above) to that note and velocity; the others, and any note while
# 'in' is off, give nothing.
heard = [[float(w) for w in l.split()[1:]] for l in log.splitlines() if l.startswith("midiin: ")]
want = [nv for nv in MIDI_IN if nv[0] in (48, 49, 50, 52, 53, 54) and nv[1] > 0]
check(len(heard) == len(want), "MIDI in: one strike per note-on of the mapping while 'in' is on "
      "(%d, want %d)" % (len(heard), len(want)))
for (note, vel), strike in zip(want, heard):
    # a strike list as ictus-receive's (19 numbers), drum 0 without a kit
    hand, speed, r, theta = strike[:4]
    speed_want = 0.1 * 100 ** ((vel - 1) / 126)
    check(len(strike) == 19 and strike[7] == 0 and
          mapping(hand, speed, r) == (note, vel) and abs(speed - speed_want) <= 1e-4 * speed_want and
          theta == (180 if hand else 0),
          "MIDI in note %d velocity %d -> hand %d, %.4f m/s, r/a %g, theta %g: maps back" %
          (note, vel, hand, speed, r, theta))
print("PASS")
