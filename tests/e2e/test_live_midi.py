#!/usr/bin/env python3
"""MIDI per instrument, live (docs/midi.md, "Live: [ictus-midi]"): `ictusd run --kit full` with
a score on every piece of the kit (kick, hi-hat closed and open, the left foot's chick, snare,
crash, ride, the three toms), the main patch (a copy of <build>/patches/ictus.pd) in the real
pd, in real time, its [ictus-midi] sending notes on channel 10. The daemon publishes its kit
(/ictus/kit/drum with each drum's General MIDI note) and each strike's drum; the patch's midi
panel must give each strike, in order, its drum's note of the General MIDI drum map as written
here (not read from ictus): snare 38, tom1 48, tom2 47, floor 43, crash 49, ride 51, hi-hat 42
(46 while the score's note has the pedal open, 44 for the left foot's chick), kick 36; its
velocity the documented curve of the strike's speed in strikes.csv. The kit message's notes are
that table's too, and so are performance.mid's of `ictusd render` of the same score. Then MIDI
in with the kit ('in' ticked, `note G V`): each General MIDI note
plays the kit's drum of that note (the strike list to ictus-kit, and a kit drum's hit line on
live-kit-hit: the main patch's is [ictus-kit live-kit]), 46 with the pedal open before it, 36
as the right foot, 44 the left foot;
`note N V G` as [ictus-midifile] sends it: G on the kit's drum, the hand from N; a note the kit
has no drum of (60; 45, a tom `full` lacks) plays nothing.

    PYTHONPATH=python python3 tests/e2e/test_live_midi.py --build build
"""
import argparse
import csv
import os
import signal
import socket
import subprocess
import tempfile
import time

from ictus_tools import e2e_util, uitest
from ictus_tools.checks import check

# The General MIDI drum map (GM Level 1, percussion key map), by the kit's piece names
# (docs/kit.md): written here, independent of ictus.
GM = {"snare": 38, "tom1": 48, "tom2": 47, "floor": 43, "crash": 49, "ride": 51, "hihat": 42,
      "kick": 36}
GM_OPEN_HIHAT, GM_PEDAL_HIHAT = 46, 44
# The score: the right hand's hi-hat notes closed, open, closed (in this order).
SCORE = """tempo 100
R on hihat 1/2 + RF
R on hihat open 1/2
R on hihat 1/2 + L on snare 1/2
L on crash 2/1 + RF
R on ride 1/2 + LF
R on ride 1/2
R on tom1 1/2
L on tom2 1/2
R on floor 1/2
L on snare
"""
HIHAT_OPEN = [False, True, False]
# MIDI in with the kit: (GM note, velocity) -> the piece, the hand, the pedal before it
MIDI_IN = [(38, 100, "snare", 1, None), (36, 90, "kick", 2, None), (46, 80, "hihat", 1, 1),
           (42, 70, "hihat", 1, 0), (44, 60, "hihat", 3, None), (49, 100, "crash", 1, None),
           (51, 64, "ride", 1, None), (43, 100, "floor", 1, None), (60, 100, None, 0, None)]
# as [ictus-midifile] sends them (note N V G): G on the kit, the hand from N (48 left, 52 right)
MIDI_IN_FILE = [(47, 90, "tom2", 0, 48), (43, 70, "floor", 1, 52), (45, 70, None, 0, 48)]


def wanted_notes(rows, names):
    """Each strike's note by the GM map above: {seq: note}. The hi-hat's hand strikes in seq
    order are the score's hi-hat notes (a bounce its stroke's), each with its note's pedal."""
    hihat_hand = [s for s in sorted(rows) if names[int(rows[s]["drum"])] == "hihat"
                  and int(rows[s]["hand"]) in (0, 1)]
    primaries = [s for s in hihat_hand if rows[s]["bounce"] == "0"]
    check(len(primaries) == len(HIHAT_OPEN), "the three hi-hat notes struck: %d" % len(primaries))
    opened, k = {}, -1
    for s in hihat_hand:
        k += rows[s]["bounce"] == "0"
        opened[s] = HIHAT_OPEN[max(0, k)]
    want = {}
    for seq, r in rows.items():
        name, hand = names[int(r["drum"])], int(r["hand"])
        want[seq] = GM[name]
        if name == "hihat":
            if hand == 3:
                want[seq] = GM_PEDAL_HIHAT
            elif opened[seq]:
                want[seq] = GM_OPEN_HIHAT
    return want


def test_patch(build, pd_port, daemon_port, ctl_port):
    """The main patch as built, with: a FUDI port (play; midiin; finish;), its midi panel on
    channel 10, prints of its notes, strikes, kit and MIDI-in strikes."""
    main, records = uitest.main_patch_on_ports(build, pd_port, daemon_port)
    n, index = uitest.top_level_index(records)
    for name in ("ictus-receive", "ictus-midi", "ictus-kit"):
        check(name in index, "the main patch has [%s]" % name)
    in_msgs = " \\, ".join(["in 1"] + ["note %d %d" % m[:2] for m in MIDI_IN] +
                            ["note %d %d %d" % (m[4], m[1], m[0]) for m in MIDI_IN_FILE] + ["in 0"])
    extra = ["#X obj 20 1000 loadbang",                                     # 0
             "#X msg 20 1030 on 1 \\, channel 10",                          # 1
             "#X obj 300 1000 netreceive -u %d" % ctl_port,                 # 2
             "#X obj 300 1030 route play midiin finish",                    # 3
             "#X msg 300 1060 play",                                        # 4
             "#X msg 400 1060 %s" % in_msgs,                                # 5
             "#X msg 500 1090 \\; pd quit",                                 # 6
             "#X obj 20 1060 print test",                                   # 7
             "#X msg 20 1090 ready",                                        # 8
             "#X obj 600 1000 r \\$0-strikes",                              # 9
             "#X obj 600 1030 t l",                                         # 10
             "#X obj 600 1060 t l",                                         # 11
             "#X obj 600 1090 print strike",                                # 12
             "#X obj 800 1000 r \\$0-kit",                                  # 13
             "#X obj 800 1030 print kit",                                   # 14
             "#X obj 900 1000 r live-kit-hit",                              # 15
             "#X obj 900 1030 print kithit",                                # 16
             "#X obj 1000 1000 r \\$0-midi-in",                             # 17
             "#X obj 1000 1030 print midiin",                               # 18
             "#X obj 700 1000 print note",                                  # 19
             "#X obj 20 1120 t b b"]                                        # 20
    links = [(0, 0, 20, 0), (20, 0, 8, 0), (8, 0, 7, 0), (2, 0, 3, 0), (3, 0, 4, 0),
             (3, 1, 5, 0), (3, 2, 6, 0), (9, 0, 10, 0), (10, 0, 11, 0), (11, 0, 12, 0),
             (13, 0, 14, 0), (15, 0, 16, 0), (17, 0, 18, 0)]
    links = [(n + a, o, n + b, i) for a, o, b, i in links]
    midi, receive = index["ictus-midi"], index["ictus-receive"]
    links += [(n + 20, 1, n + 1, 0), (n + 1, 0, midi, 0), (n + 5, 0, midi, 0),
              (midi, 0, n + 19, 0), (n + 4, 0, receive, 0)]
    return (";\n".join(records) + ";\n" + "".join(e + ";\n" for e in extra)
            + "".join("#X connect %d %d %d %d;\n" % l for l in links))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", required=True)
    ap.add_argument("--ictusd", default="")
    args = ap.parse_args()
    build = os.path.abspath(args.build)
    ictusd = args.ictusd or os.path.join(build, "ictusd")
    pd_port, daemon_port, ctl_port = (uitest.free_udp_port() for _ in range(3))
    lines = uitest.PdLines()
    work = tempfile.mkdtemp(prefix="ictus-live-midi-")
    score = os.path.join(work, "kit.txt")
    with open(score, "w") as f:
        f.write(SCORE)
    patch = os.path.join(work, "ictus.pd")
    with open(patch, "w") as f:
        f.write(test_patch(build, pd_port, daemon_port, ctl_port))
    ctl = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    pd = daemon = None
    kit, notes, strikes, speeds = {}, [], [], {}
    try:
        pd = subprocess.Popen([uitest.PD, "-nogui", "-nosound", "-nomidi", "-nrt", "-stderr",
                               "-path", os.path.join(build, "ictus"), "-open", patch],
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                              env=uitest.PD_ENV)
        lines.follow(pd.stdout)
        lines.wait_for(lambda l: l == "test: ready", "the patch open")
        env = dict(os.environ)
        env.pop("LD_PRELOAD", None)  # pd's ASan preload is not the daemon's
        log = open(os.path.join(work, "ictusd.log"), "w")
        daemon = subprocess.Popen([ictusd, "run", "--kit", "full", "--score", score,
                                   "--port", str(daemon_port),
                                   "--target", "osc.udp://127.0.0.1:%d" % pd_port,
                                   "--reply", "osc.udp://127.0.0.1:%d" % pd_port,
                                   "--pose-rate", "0", "--lookahead", "0.05", "--out", work],
                                  stdout=log, stderr=subprocess.STDOUT, env=env)
        # the kit, sent as the daemon starts: its name and count, then one line per drum
        head = lines.wait_for(lambda l: l.startswith("kit: full"), "the kit's name", 120)
        count = int(float(head.split()[2]))
        while len(kit) < count:
            w = lines.wait_for(lambda l: l.startswith("kit: drum "), "the kit's drums").split()
            kit[int(float(w[2]))] = (w[3], int(float(w[-1])))
        ctl.sendto(b"play;\n", ("127.0.0.1", ctl_port))
        # the strikes and notes as they come, until 6 s without one after the first (the
        # score lasts 6 s, its longest gap 1.2 s), within 180 s
        start, last = time.time(), None
        while time.time() - start < 180 and (last is None or time.time() - last < 6.0):
            line = lines.next_line(0.2)
            if line is None:
                break  # pd ended: the checks below say what is missing
            w = line.split() or [""]
            if w[0] == "strike:":
                strikes.append(int(float(w[9])))
                speeds[strikes[-1]] = float(w[2])
                last = time.time()
            elif w[0] == "note:":
                notes.append(tuple(int(float(x)) for x in w[1:]))
        daemon.send_signal(signal.SIGINT)  # strikes.csv complete
        daemon.wait(60)
        ctl.sendto(b"midiin;\n", ("127.0.0.1", ctl_port))
        lines.wait_for(lambda l: l.startswith("midiin: ") and l.split()[1] == "3",
                       "the chick from MIDI in", 30)
        ctl.sendto(b"finish;\n", ("127.0.0.1", ctl_port))
        pd.wait(30)
    finally:
        if daemon is not None and daemon.poll() is None:
            daemon.kill()
            daemon.wait()
        uitest.stop(pd)
    lines.drain()  # what pd printed last
    with open(os.path.join(work, "strikes.csv")) as f:
        rows = {int(r["seq"]): r for r in csv.DictReader(f)}
    # the kit as published: each drum's note is the GM map's
    names = {i: name for i, (name, _) in kit.items()}
    check(sorted(names.values()) == sorted(GM) and
          all(note == GM[name] for name, note in kit.values()),
          "the kit's /ictus/kit/drum notes are the General MIDI map's: %s" % kit)
    check(len(strikes) == len(rows) and sorted(strikes) == sorted(rows),
          "every strike of strikes.csv reached the patch (%d, %d in strikes.csv)"
          % (len(strikes), len(rows)))
    check(len(notes) == len(strikes), "one note per strike (%d notes, %d strikes)"
          % (len(notes), len(strikes)))
    seen = set()
    wanted = wanted_notes(rows, names)
    for seq, (note, vel, channel, bounce) in zip(strikes, notes):
        r = rows[seq]
        name, hand, want = names[int(r["drum"])], int(r["hand"]), wanted[seq]
        seen.add(want)
        vels = e2e_util.midi_velocities(float(r["normal_velocity_mps"]))
        check((note, channel, bounce) == (want, 10, int(r["bounce"])) and vel in vels,
              "strike %d (%s, hand %d, %s m/s; %.4f m/s in the patch): note %d velocity %d "
              "channel %d, want %d %s 10"
              % (seq, name, hand, r["normal_velocity_mps"], speeds[seq], note, vel, channel, want,
                 " or ".join(map(str, sorted(vels)))))
    check({36, 42, 44, 46, 38, 49, 48, 47, 43} <= seen,
          "kick, hi-hat closed and open, chick, snare, crash and toms among them: %s"
          % sorted(seen))
    # the render of the same score: performance.mid (read by mido) by the same map
    mido = e2e_util.require_mido()
    out = os.path.join(work, "render")
    env = dict(os.environ)
    env.pop("LD_PRELOAD", None)
    proc = subprocess.run([ictusd, "render", "--kit", "full", "--score", score, "--out", out,
                           "--bvh-rate", "0", "--tips-rate", "0"], capture_output=True, text=True,
                          timeout=300, env=env)
    check(proc.returncode == 0, "ictusd render ran: %s" % proc.stderr[-500:])
    with open(os.path.join(out, "strikes.csv")) as f:
        rendered = {int(r["seq"]): r for r in csv.DictReader(f)}
    file_notes = [m.note for m in mido.MidiFile(os.path.join(out, "performance.mid"))
                  if m.type == "note_on" and m.velocity > 0]
    want_file = wanted_notes(rendered, names)
    check(file_notes == [want_file[s] for s in sorted(rendered)],
          "performance.mid of the same score: each strike its drum's note by the same map "
          "(46 open, 44 the chick): %s" % file_notes)
    # MIDI in with the kit: each note on the kit's drum of that note
    drum_of = {name: i for i, name in names.items()}
    heard = [[float(x) for x in l.split()[1:]] for l in lines.printed if l.startswith("midiin: ")]
    want_in = [m for m in MIDI_IN + MIDI_IN_FILE if m[2] is not None]
    check(len(heard) == len(want_in), "MIDI in: one strike per note the kit has (%d, want %d)"
          % (len(heard), len(want_in)))
    for (note, vel, name, hand, _), h in zip(want_in, heard):
        speed = 0.1 * 100 ** ((vel - 1) / 126)
        check(len(h) == 19 and int(h[7]) == drum_of[name] and int(h[0]) == hand and
              abs(h[1] - speed) <= 1e-4 * speed,
              "MIDI in note %d -> %s (drum %d), hand %d, %.4f m/s: %s"
              % (note, name, drum_of[name], hand, speed, h[:8]))
    pedals = [l for l in lines.printed if l.startswith("kit: pedal ")]
    hihat = drum_of["hihat"]
    check(pedals[-2:] == ["kit: pedal %d 1" % hihat, "kit: pedal %d 0" % hihat],
          "MIDI in's 46 opens the hi-hat's pedal, its 42 closes it: %s" % pedals[-2:])
    kithits = [l for l in lines.printed if l.startswith("kithit: ")]
    check(len(kithits) >= 1 and any(int(float(l.split()[2])) == drum_of["crash"]
                                    for l in kithits[-8:]),
          "MIDI in's strikes reach the kit's drums (live-kit-hit): %s" % kithits[-8:])
    bad = uitest.error_lines("\n".join(lines.printed))
    check(not bad, "no error lines from pd: %s" % bad)
    print("PASS")


if __name__ == "__main__":
    main()
