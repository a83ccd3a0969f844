#!/usr/bin/env python3
"""A kit played live (docs/kit.md, "Playing it live"): `ictusd run --kit standard` with a score
on its four drums, the main patch (a copy of <build>/patches/ictus.pd) in the real pd, in real
time, recording what goes to its dac~. The daemon sends its kit (/ictus/kit, /ictus/kit/drum)
and each strike's drum; the patch plays drum 0 on its sound and drums 1..3 each on its own
[ictus-kit-drum] (membrane~ + contact~ pair) with the kit's preset. Checked: the kit reaches
the patch (drum 0's sound gets the snare preset, drums 1..3 are switched on), every primary
strike of strikes.csv arrives, with its stick tip (felt, in strikes.csv and in the strike list,
which gives it to every drum's sticks), and each sounds loudest at its own drum's lowest mode: of the
four drums' (0,1) frequencies, f01 = j01 / (2 pi a) sqrt(T / sigma) from each preset's head
(externals/core/membrane_presets.c; the 10-inch tom1 is the tom preset's head on a 10-inch
shell, docs/kit.md; the toms' with the air's mass on both faces, ictus_tools.drumtone.f01), the one with the most energy (Goertzel) in the 150 ms after its onset.
The onset is where the patch played it: the strike's logical time, printed by the patch,
from the start of the recording (the play message, however long the daemon took to start). Every wait is a handshake on pd's printed lines or the
daemon's exit, with a deadline.

    PYTHONPATH=python python3 tests/e2e/test_live_kit.py --build build
"""
import argparse
import csv
import os
import signal
import socket
import subprocess
import tempfile

import numpy as np

from ictus_tools import uitest
from ictus_tools.checks import check
from ictus_tools.drumtone import f01, goertzel_power
from ictus_tools.pdrun import read_wav_float

TEMPO = 100
SCORE = """tempo %d
drum snare
R, L, R, L
drum tom1
L, R
R on tom2, L on tom2
drum floor
R at 0.3 0, R at 0.3 0
R on snare, L on snare
R on tom1, L on tom2, R on snare, L on snare
""" % TEMPO
NOTES = 16
# The kit's drums (docs/kit.md's table): name, (radius m, tension N/m, density kg/m^2) of the
# preset's head on the kit's shell.
HEADS = [("snare", (0.1778, 3603.0, 0.345)), ("tom1", (0.127, 1465.7, 0.491, 2.0)),
         ("tom2", (0.1524, 1465.7, 0.491, 2.0)), ("floor", (0.2032, 878.0, 0.345))]
TIP, TIP_CODE = "felt", 3  # the sticks' tip and its code in the strike record (docs/osc.md)
SR = 48000
RECORD_S = 180  # the recording's length (s): the score is 11 s after play, longer when the
# daemon runs slower than real time (the sanitizer build on a loaded machine)




def test_patch(build, pd_port, daemon_port, ctl_port, wav):
    """The main patch as built, listening on pd_port, sending to daemon_port, with what the
    test adds at its end: a FUDI port (play; finish;), the recording of the dac~'s two inputs
    from the play message on, each strike's logical time since then, and prints of the kit."""
    main, records = uitest.main_patch_on_ports(build, pd_port, daemon_port)
    n, index = uitest.top_level_index(records)
    for name in ("ictus-receive", "ictus-kit", "ictus-sound"):
        check(name in index, "the main patch has [%s]" % name)
    extra = ["#X obj 20 1000 loadbang",                                     # 0
             "#X obj 200 1200 tabwrite~ live-r",                            # 1
             "#X obj 20 1200 tabwrite~ live-l",                             # 2
             "#X obj 300 1000 netreceive -u %d" % ctl_port,                 # 3
             "#X obj 300 1030 route play finish",                           # 4
             "#X msg 300 1060 play",                                        # 5
             "#X obj 400 1060 delay 1500",                                  # 6
             "#X obj 400 1090 t b b b",                                     # 7
             "#X obj 600 1000 t b l",                                       # 8
             "#X obj 600 1030 timer",                                       # 9
             "#X obj 700 1030 list split 6",                                # 10
             "#X obj 700 1060 list split 3",                                # 11
             "#X obj 600 1090 pack f 0 0 0 0",                              # 12
             "#X obj 700 1090 unpack f f f",                                # 13
             "#X obj 600 1120 print strike",                                # 14
             "#X obj 20 1120 print test",                                   # 15
             "#X msg 20 1150 ready",                                        # 16
             "#X obj 900 1000 r live-kit-3",                                # 17
             "#X obj 900 1030 print kit3",                                  # 18
             "#X obj 900 1060 route preset",                                # 19
             "#X obj 900 1090 print drum0-preset",                          # 20
             "#X msg 400 1120 recorded",                                    # 21
             "#X msg 480 1120 write -wave -bytes 4 %s live-l live-r" % wav,  # 22
             "#X msg 560 1150 \\; pd quit",                               # 23
             "#X obj 480 1150 soundfiler",                                  # 24
             "#X obj 20 1250 array define live-l %d" % (RECORD_S * SR),     # 25
             "#X obj 200 1250 array define live-r %d" % (RECORD_S * SR),    # 26
             "#X obj 900 1130 list split 18",                               # 27
             "#X obj 900 1160 list split 1",                                # 28
             "#X obj 300 1090 t b b"]                                       # 29
    base = n
    # Recording from play (however long the daemon took to start) into two arrays; finish:
    # 1.5 s of ringing on pd's clock, then the arrays written (soundfiler: done when it
    # returns), "recorded", and pd quits.
    links = [(29, 1, 1, 0), (29, 1, 2, 0), (3, 0, 4, 0), (4, 0, 29, 0), (29, 0, 5, 0),
             (4, 1, 6, 0), (6, 0, 7, 0),
             (7, 2, 22, 0), (22, 0, 24, 0), (7, 1, 21, 0), (21, 0, 15, 0), (7, 0, 23, 0),
             (8, 0, 9, 1), (8, 1, 10, 0), (10, 1, 11, 0), (11, 0, 13, 0), (13, 0, 12, 1),
             (13, 1, 12, 2), (13, 2, 12, 3), (9, 0, 12, 0), (12, 0, 14, 0), (29, 1, 9, 0),
             (0, 0, 16, 0), (16, 0, 15, 0), (17, 0, 18, 0), (19, 0, 20, 0), (8, 1, 27, 0),
             (27, 1, 28, 0), (28, 0, 12, 4)]
    links = [(base + a, o, base + b, i) for a, o, b, i in links]
    sound, kit, receive = (index[k] for k in ("ictus-sound", "ictus-kit", "ictus-receive"))
    links += [(sound, 0, base + 2, 0), (sound, 1, base + 1, 0), (kit, 1, base + 2, 0),
              (kit, 2, base + 1, 0), (base + 5, 0, receive, 0), (receive, 0, base + 8, 0),
              (kit, 0, base + 19, 0)]
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
    work = tempfile.mkdtemp(prefix="ictus-live-kit-")
    wav = os.path.join(work, "live.wav")
    score = os.path.join(work, "kit.txt")
    with open(score, "w") as f:
        f.write(SCORE)
    patch = os.path.join(work, "ictus.pd")
    with open(patch, "w") as f:
        f.write(test_patch(build, pd_port, daemon_port, ctl_port, wav))
    ctl = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    pd = daemon = None
    strikes_pd = {}
    try:
        # -nrt: as root pd takes real-time priority, and a sanitizer build's DSP, slower than
        # real time, then starves the daemon and the other tests on the cores
        pd = subprocess.Popen([uitest.PD, "-nogui", "-nosound", "-nomidi", "-nrt", "-stderr",
                               "-r", str(SR), "-path", os.path.join(build, "ictus"), "-open", patch,
                               "-send", "pd dsp 1"], stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True, env=uitest.PD_ENV)
        lines.follow(pd.stdout)
        lines.wait_for(lambda l: l == "test: ready", "the patch open")
        env = dict(os.environ)
        env.pop("LD_PRELOAD", None)  # pd's ASan preload is not the daemon's
        log = open(os.path.join(work, "ictusd.log"), "w")
        daemon = subprocess.Popen([ictusd, "run", "--kit", "standard", "--score", score,
                                   "--port", str(daemon_port),
                                   "--target", "osc.udp://127.0.0.1:%d" % pd_port,
                                   "--reply", "osc.udp://127.0.0.1:%d" % pd_port,
                                   "--pose-rate", "0", "--lookahead", "0.05", "--out", work,
                                   "--stick-tip", TIP],
                                  stdout=log, stderr=subprocess.STDOUT, env=env)
        # the kit, sent as the daemon starts: drum 0's preset to the sound, drum 3 switched on
        lines.wait_for(lambda l: l == "drum0-preset: snare", "drum 0's sound set to snare", 120)
        lines.wait_for(lambda l: l == "kit3: dsp 1", "the kit's drum 3 switched on")
        ctl.sendto(b"play;\n", ("127.0.0.1", ctl_port))
        primaries = 0
        while primaries < NOTES:
            line = lines.wait_for(lambda l: l.startswith("strike: "), "strike %d" % primaries, 60)
            ms, bounce, drum, seq, tip = (float(w) for w in line.split()[1:])
            strikes_pd[int(seq)] = (ms, int(drum), int(tip))
            primaries += bounce == 0
        daemon.send_signal(signal.SIGINT)  # strikes.csv complete: the daemon ends its contacts
        daemon.wait(60)
        ctl.sendto(b"finish;\n", ("127.0.0.1", ctl_port))
        lines.wait_for(lambda l: l == "test: recorded", "the recording closed")
        pd.wait(30)
    finally:
        if daemon is not None and daemon.poll() is None:
            daemon.kill()
            daemon.wait()
        uitest.stop(pd)
    with open(os.path.join(work, "strikes.csv")) as f:
        rows = [r for r in csv.DictReader(f) if r["bounce"] == "0"]
    check(len(rows) == NOTES, "strikes.csv: %d primary strikes for %d notes" % (len(rows), NOTES))
    check(all(int(r["stick_tip"]) == TIP_CODE for r in rows), "strikes.csv: every strike's tip "
          "is %s (%d)" % (TIP, TIP_CODE))
    check(all(v[2] == TIP_CODE for v in strikes_pd.values()), "every strike list in the patch "
          "carries the tip %d" % TIP_CODE)
    for hand in ("left", "right"):
        check("kit3: %s tip %s" % (hand, TIP) in lines.printed,
              "the kit's drum 3 gets the tip on its %s stick" % hand)
    x, rate = read_wav_float(wav)
    check(rate == SR and np.all(np.isfinite(x)), "the recording: %d Hz, finite" % rate)
    mono = x.mean(axis=1)
    freq = {name: f01(*head) for name, head in HEADS}
    right, heard = 0, []
    # A strike is judged alone: when another arrived within its window (a daemon slower than
    # real time, as under the sanitizer, delivers late strikes together), the louder one wins
    # and says nothing of routing; nor when another arrived less than 0.9 of the score's beat
    # before it (closer than the score spaces them: a tom's ring outlasts a snare's fundamental,
    # T60 0.11 s, in the window). Every strike is judged when they arrive on time.
    arrived = sorted(v[0] for v in strikes_pd.values())
    beat_ms = 60000.0 / TEMPO
    alone = []
    for r in rows:
        seq, drum = int(r["seq"]), int(r["drum"])
        check(seq in strikes_pd and strikes_pd[seq][1] == drum,
              "strike %d arrived in the patch on drum %d" % (seq, drum))
        t = strikes_pd[seq][0]
        if any(t < a <= t + 155.0 or t - 0.9 * beat_ms < a < t for a in arrived):
            continue
        alone.append(r)
    check(len(alone) >= len(rows) // 2, "at least half the strikes arrive alone in their "
          "150 ms window, none less than 0.9 beat before (%d of %d)" % (len(alone), len(rows)))
    for r in alone:
        seq, drum = int(r["seq"]), int(r["drum"])
        i0 = int(round(strikes_pd[seq][0] * rate / 1000.0)) + int(0.005 * rate)
        seg = mono[i0:i0 + int(0.15 * rate)]
        check(len(seg) == int(0.15 * rate), "strike %d's window lies in the recording" % seq)
        power = {k: goertzel_power(seg, rate, f) for k, f in freq.items()}
        loudest = max(power, key=power.get)
        heard.append((seq, HEADS[drum][0], loudest))
        right += loudest == HEADS[drum][0]
    print("strike, drum, loudest mode: %s" % heard)
    check(right == len(alone), "each strike sounds loudest at its drum's lowest mode: %d of %d "
          "(modes %s Hz)" % (right, len(alone), {k: round(v, 1) for k, v in freq.items()}))
    bad = uitest.error_lines("\n".join(lines.printed))
    check(not bad, "no error lines from pd: %s" % bad)
    print("PASS")


if __name__ == "__main__":
    main()
