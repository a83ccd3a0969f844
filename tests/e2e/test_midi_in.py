"""`ictusd render --midi FILE` (docs/midi.md, "MIDI in"): a General MIDI drum
part made here (an SMF format 1 written by this test's own few lines, 480
ticks a quarter, 110 bpm, 4/4, channel 10) rendered on the standard kit and on
the one drum, held against strikes.csv:
- every snare and tom note is struck once (bounces aside), in order, within
  5 ms of its time computed here: lead-in + tick / 480 x 60 / 110 s;
- drums by the General MIDI map and the kit's notes (snare 38 and 40 -> snare;
  tom 50 -> tom1 (48); 47 -> tom2; 45 -> tom2 (47 and 43 both 2 away: the
  kit's first); 43 and 41 -> floor (43)); without --kit all on the one drum;
- hands as documented: notes under 0.3 s apart alternate, farther apart the
  right hand; two at one tick: the other hand; computed here from the ticks;
- side stick 37 is the snare's rim: the snare, aimed at r/a 0.95, and the strike the
  physics reports is on the rim (zone 1);
- kick, hi-hat and crash are left out with one warning line counting them per
  note number ("note 36 x2, note 42 x8, note 49 x1");
- one note left out of each kind, one tempo kept within bounds: said in the
  singular ("1 note the drum cannot play left out");
- a file cut short or with a bad chunk: exit 1 naming the byte and track,
  no crash."""
import argparse
import json
import os
import struct
import subprocess

from ictus_tools import e2e_util as u
from ictus_tools.checks import check
from ictus_tools.pdrun import make_workdir

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
ictusd = os.path.join(os.path.abspath(args.build), "ictusd")
work = make_workdir("ictus-midi-in-")
env = dict(os.environ)
env.pop("LD_PRELOAD", None)

TPQ, BPM = 480, 110.0
US = round(60e6 / BPM)


def vlq(v):
    out = [v & 0x7F]
    v >>= 7
    while v:
        out.append(0x80 | (v & 0x7F))
        v >>= 7
    return bytes(reversed(out))


def track(events):
    data, last = b"", 0
    for tick, msg in sorted(events, key=lambda e: (e[0], e[1][0] & 0xF0 == 0x90)):
        data += vlq(tick - last) + msg
        last = tick
    data += b"\x00\xff\x2f\x00"
    return b"MTrk" + struct.pack(">I", len(data)) + data


# (tick, note, velocity): a bar of 8ths on the snare with kick and hi-hat, a
# bar of 16ths across the toms, and a snare with a floor tom (and a crash) at once.
notes = []
for k in range(8):
    notes += [(k * 240, 38, 72 if k % 2 == 0 else 64), (k * 240, 42, 80)]
notes += [(0, 36, 100), (960, 36, 100)]
for k, n in enumerate([38, 38, 40, 38, 50, 50, 47, 47, 45, 45, 43, 43, 41, 41, 43, 43]):
    notes.append((1920 + 120 * k, n, 40 + 5 * k))
notes += [(3840, 38, 127), (3840, 43, 110), (3840, 49, 120)]
notes += [(4800 + 480 * k, 37, 90) for k in range(4)]  # a bar of side sticks on the beats
meta = [(0, b"\xff\x51\x03" + US.to_bytes(3, "big")), (0, b"\xff\x58\x04\x04\x02\x18\x08")]
drum = [(t, bytes([0x99, n, v])) for t, n, v in notes] + [(t + 60, bytes([0x89, n, 0])) for t, n, v in notes]
smf = b"MThd" + struct.pack(">IHHH", 6, 1, 2, TPQ) + track(meta) + track(drum)
path = os.path.join(work, "part.mid")
with open(path, "wb") as f:
    f.write(smf)

# What the test expects, from the file's notes: the playable ones in file order
# (ties: the order written), their times, hands and drums.
KIT = {37: "snare", 38: "snare", 40: "snare", 50: "tom1", 48: "tom1", 47: "tom2", 45: "tom2", 43: "floor", 41: "floor"}
KIT_INDEX = {"snare": 0, "tom1": 1, "tom2": 2, "floor": 3}
played = sorted([(t, n, v) for t, n, v in notes if n in KIT], key=lambda e: e[0])
want = []
last_t, last_tick, last_hand = None, None, 1
for t, n, v in played:
    sec = t / TPQ * 60.0 / BPM
    if t == last_tick:
        hand = 1 - last_hand
    else:
        hand = 1 - last_hand if last_t is not None and sec - last_t < 0.3 else 1
    want.append((sec, hand, KIT[n], n))
    last_t, last_tick, last_hand = sec, t, hand


def render(name, extra):
    out = os.path.join(work, name)
    proc = subprocess.run([ictusd, "render", "--midi", path, "--out", out, "--bvh-rate", "0",
                           "--tips-rate", "0"] + extra,
                          capture_output=True, text=True, timeout=600, env=env)
    check(proc.returncode == 0, "ictusd render --midi %s ran: %s" % (" ".join(extra), proc.stderr[-2000:]))
    with open(os.path.join(out, "render.json")) as f:
        plan = json.load(f)["performance"]["plan"]
    lead = plan["origin_s"] + plan["lead_in_s"]  # the render time of the file's tick 0
    strikes = [s for s in u.read_strikes(os.path.join(out, "strikes.csv")) if not s["bounce"]]
    return proc, lead, strikes


for name, extra in (("kit", ["--kit", "standard"]), ("one", [])):
    proc, lead, strikes = render(name, extra)
    warn = [ln for ln in proc.stderr.splitlines() if "cannot play" in ln]
    check(len(warn) == 1 and "11 notes" in warn[0] and "note 36 x2, note 42 x8, note 49 x1" in warn[0],
          "one warning line counting the notes left out per number (%s)" % warn)
    check(len(strikes) == len(want), "one strike per playable note (%d strikes, %d notes)"
          % (len(strikes), len(want)))
    # Two at one tick come in either order: compare each tick's strikes as a set.
    worst = 0.0
    for s, (sec, hand, d, n) in zip(strikes, want):
        worst = max(worst, abs(s["time_s"] - lead - sec))
    check(worst <= 5e-3, "%s: every note struck within 5 ms of its time (worst %.2f ms)" % (name, worst * 1e3))
    # Strike k is note k; notes at one tick may strike in either order: each
    # tick's (hand, drum) pairs are compared as sets.
    got, exp = {}, {}
    for s, (sec, hand, d, n) in zip(strikes, want):
        got.setdefault(sec, []).append((s["hand"], s["drum"]))
        exp.setdefault(sec, []).append((hand, KIT_INDEX[d] if name == "kit" else 0))
    got = {k: sorted(v) for k, v in got.items()}
    exp = {k: sorted(v) for k, v in exp.items()}
    check(got == exp, "%s: hands and drums as documented (%s)" % (
        name, [(k, got[k], exp[k]) for k in sorted(exp) if got.get(k) != exp[k]]))
    rims = [(s["r_over_a"], s["zone"]) for s, w in zip(strikes, want) if w[3] == 37]
    check(len(rims) == 4 and all(z == 1 for _, z in rims),
          "%s: every side stick lands on the snare's rim (r/a, zone: %s)" % (name, rims))
    heads = [s["zone"] for s, w in zip(strikes, want) if w[3] != 37]
    check(all(z == 0 for z in heads), "%s: every other note on a head (zones %s)" % (name, heads))
    print("%s: %d notes, worst |strike - file time| %.2f ms" % (name, len(strikes), worst * 1e3))

# One of each thing counted on stderr is said in the singular ("1 notes" before): a kick
# the one drum cannot play, a third note at one tick, a note on channel 1 beside channel
# 10's, a tempo past 400 bpm.
one = [(0, b"\xff\x51\x03" + round(60e6 / 500).to_bytes(3, "big"))]
one += [(0, bytes([0x99, 36, 100])), (480, bytes([0x99, 38, 100])), (480, bytes([0x99, 40, 100])),
        (480, bytes([0x99, 50, 100])), (960, bytes([0x90, 38, 100]))]
single = os.path.join(work, "single.mid")
with open(single, "wb") as f:
    f.write(b"MThd" + struct.pack(">IHHH", 6, 0, 1, TPQ) + track(one))
proc = subprocess.run([ictusd, "render", "--midi", single, "--out", os.path.join(work, "single"),
                       "--bvh-rate", "0", "--tips-rate", "0"],
                      capture_output=True, text=True, timeout=300, env=env)
check(proc.returncode == 0, "a part of three notes plays (%s)" % proc.stderr[-2000:])
for said in ("single.mid: 1 note the drum cannot play left out (note 36 x1)",
             "single.mid: 1 note left out: no hand free",
             "single.mid: 1 note on a channel other than 10 left out",
             "single.mid: 1 tempo kept within 20..400 bpm",
             "single.mid: 2 notes from channel 10"):
    check(said in proc.stderr, "stderr says '%s' (%s)" % (said, proc.stderr.strip()))

for cut, what in ((smf[:40], "cut short"), (smf[:14] + b"MTrk\xff\xff\xff\xff", "bad chunk length")):
    bad = os.path.join(work, "bad.mid")
    with open(bad, "wb") as f:
        f.write(cut)
    proc = subprocess.run([ictusd, "render", "--midi", bad, "--out", os.path.join(work, "bad"),
                           "--force"], capture_output=True, text=True, timeout=60, env=env)
    check(proc.returncode == 1 and "byte" in proc.stderr and "bad.mid" in proc.stderr,
          "a file %s: exit 1 naming the byte (%d: %s)" % (what, proc.returncode, proc.stderr.strip()))
print("PASS")
