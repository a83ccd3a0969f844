#!/usr/bin/env python3
"""Live sounds as the render does (docs/pd-osc.md, "The output stage"): the main patch (a copy of
<build>/patches/ictus.pd) in the real pd, in real time, playing the daemon's default score from
`ictusd run`, recorded at its dac~ (the two outlets of its [ictus-out~]) from the play message
on; and `ictusd render --wav` of the same score. Checked on the recording: the peak at most
-0.3 dBFS (the limiter's ceiling is -0.5), the two channels' RMS within 1.5 dB of each other,
and the level of the sounding part (the RMS from the first to the last sample above 1e-3) within
2 dB of the render's, measured the same way. The Pd window is quiet by default: no strike
telemetry (`ictusd: strike end ...`) while the physics panel's verbose is off (the first half of
the strikes); once it is turned on through its receive name, the strike ends are printed. Every wait is a handshake on pd's printed lines or
the daemon's output, with a deadline.

    PYTHONPATH=python python3 tests/e2e/test_live_output.py --build build
"""
import argparse
import os
import socket
import subprocess
import tempfile

import numpy as np

from ictus_tools import e2e_util, uitest
from ictus_tools.checks import check
from ictus_tools.pdrun import read_wav_float

SR = 48000
PEAK_DBFS, CHANNELS_DB, LEVEL_DB = -0.3, 1.5, 2.0  # the acceptance's bounds
SOUNDING = 1e-3  # a sample louder than this (-60 dBFS) belongs to the sounding part


def test_patch(build, pd_port, daemon_port, ctl_port, wav, seconds):
    """The main patch as built, on the test's ports, with at its end: a FUDI port (play;
    finish;), the recording of ictus-out~'s two outlets (what dac~ plays) from play on."""
    main, records = uitest.main_patch_on_ports(build, pd_port, daemon_port)
    n, index = uitest.top_level_index(records)
    for name in ("ictus-receive", "ictus-out~", "dac~"):
        check(name in index, "the main patch has [%s]" % name)
    out = index["ictus-out~"]
    check("#X connect %d 0 %d 0" % (out, index["dac~"]) in main
          and "#X connect %d 1 %d 1" % (out, index["dac~"]) in main,
          "[ictus-out~] feeds the dac~")
    extra = ["#X obj 20 1000 loadbang",                                    # 0
             "#X obj 200 1200 tabwrite~ live-r",                           # 1
             "#X obj 20 1200 tabwrite~ live-l",                            # 2
             "#X obj 300 1000 netreceive -u %d" % ctl_port,                # 3
             "#X obj 300 1030 route play finish verbose",                  # 4
             "#X msg 300 1060 play",                                       # 5
             "#X obj 400 1060 delay 1500",                                 # 6
             "#X obj 400 1090 t b b b",                                    # 7
             "#X obj 20 1120 print test",                                  # 8
             "#X msg 20 1150 ready",                                       # 9
             "#X msg 400 1120 recorded",                                   # 10
             "#X msg 480 1120 write -wave -bytes 4 %s live-l live-r" % wav,  # 11
             "#X msg 560 1150 \\; pd quit",                               # 12
             "#X obj 480 1150 soundfiler",                                 # 13
             "#X obj 20 1250 array define live-l %d" % (seconds * SR),     # 14
             "#X obj 200 1250 array define live-r %d" % (seconds * SR),    # 15
             "#X obj 300 1090 t b b",                                      # 16
             "#X obj 600 1000 print strike",                               # 17
             "#X obj 700 1060 s ictus-physics-verbose"]                    # 18
    links = [(16, 1, 1, 0), (16, 1, 2, 0), (3, 0, 4, 0), (4, 0, 16, 0), (16, 0, 5, 0),
             (4, 1, 6, 0), (6, 0, 7, 0), (7, 2, 11, 0), (11, 0, 13, 0), (7, 1, 10, 0),
             (10, 0, 8, 0), (7, 0, 12, 0), (0, 0, 9, 0), (9, 0, 8, 0), (4, 2, 18, 0)]
    links = [(n + a, o, n + b, i) for a, o, b, i in links]
    links += [(out, 0, n + 2, 0), (out, 1, n + 1, 0), (n + 5, 0, index["ictus-receive"], 0),
              (index["ictus-receive"], 0, n + 17, 0)]
    return (";\n".join(records) + ";\n" + "".join(e + ";\n" for e in extra)
            + "".join("#X connect %d %d %d %d;\n" % l for l in links))


def sounding_rms_db(x):
    """RMS (dBFS) of the part from the first to the last sample above SOUNDING, both channels."""
    loud = np.nonzero(np.abs(x).max(axis=1) > SOUNDING)[0]
    check(len(loud) > 0, "the recording sounds")
    part = x[loud[0]:loud[-1] + 1]
    return 10.0 * np.log10(np.mean(part ** 2)), part


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", required=True)
    ap.add_argument("--ictusd", default="")
    args = ap.parse_args()
    build = os.path.abspath(args.build)
    ictusd = args.ictusd or os.path.join(build, "ictusd")
    env = dict(os.environ)
    env.pop("LD_PRELOAD", None)  # pd's ASan preload is not the daemon's
    work = tempfile.mkdtemp(prefix="ictus-live-output-")
    render_dir = os.path.join(work, "render")
    render = subprocess.run([ictusd, "render", "--out", render_dir, "--wav",
                             os.path.join(render_dir, "p.wav")],
                            env=e2e_util.pd_spawning_env(work),
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            timeout=600)
    check(render.returncode == 0, "ictusd render --wav of the default score: %s"
          % render.stdout[-400:])
    ref, rate = read_wav_float(os.path.join(render_dir, "p.wav"))
    check(rate == SR, "the render at %d Hz" % rate)
    length_s = len(ref) / SR
    with open(os.path.join(render_dir, "strikes.csv")) as f:
        n_strikes = len(f.readlines()) - 1
    check(n_strikes >= 4, "the render has strikes (%d)" % n_strikes)
    seconds = int(length_s + 12)
    pd_port, daemon_port, ctl_port = (uitest.free_udp_port() for _ in range(3))
    lines = uitest.PdLines()
    wav = os.path.join(work, "live.wav")
    patch = os.path.join(work, "ictus.pd")
    with open(patch, "w") as f:
        f.write(test_patch(build, pd_port, daemon_port, ctl_port, wav, seconds))
    ctl = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    pd = daemon = None
    try:
        # -nrt: as root pd takes real-time priority, and a sanitizer build's DSP, slower than
        # real time, then starves the daemon and the other tests on the cores
        pd = subprocess.Popen([uitest.PD, "-nogui", "-nosound", "-nomidi", "-nrt", "-stderr",
                               "-r", str(SR), "-path", os.path.join(build, "ictus"), "-open", patch,
                               "-send", "pd dsp 1"], stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True, env=uitest.PD_ENV)
        lines.follow(pd.stdout)
        lines.wait_for(lambda l: l == "test: ready", "the patch open")
        # the daemon plays its default score for the render's length and ends by itself
        daemon = subprocess.Popen([ictusd, "run", "--port", str(daemon_port),
                                   "--target", "osc.udp://127.0.0.1:%d" % pd_port,
                                   "--reply", "osc.udp://127.0.0.1:%d" % pd_port,
                                   "--pose-rate", "0", "--lookahead", "0.05",
                                   "--duration", "%g" % (length_s + 4.0)],
                                  stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                  env=env)
        dlines = uitest.PdLines("ictusd")
        dlines.follow(daemon.stdout)
        dlines.wait_for(lambda l: "commands on 127.0.0.1:%d" % daemon_port in l,
                        "the daemon listening", 120)
        ctl.sendto(b"play;\n", ("127.0.0.1", ctl_port))
        for k in range(n_strikes // 2):
            lines.wait_for(lambda l: l.startswith("strike: "), "strike %d" % k, 60)
        quiet = [l for l in lines.printed if l.startswith("ictusd: strike")]
        ctl.sendto(b"verbose 1;\n", ("127.0.0.1", ctl_port))
        lines.wait_for(lambda l: l.startswith("ictusd: strike end"), "a strike end printed, verbose")
        daemon.wait(length_s * 4 + 120)
        ctl.sendto(b"finish;\n", ("127.0.0.1", ctl_port))
        lines.wait_for(lambda l: l == "test: recorded", "the recording closed")
        pd.wait(30)
    finally:
        if daemon is not None and daemon.poll() is None:
            daemon.kill()
            daemon.wait()
        uitest.stop(pd)
    check(not quiet, "quiet by default: no strike telemetry in the Pd window over %d strikes: %s"
          % (n_strikes // 2, quiet[:3]))
    x, rate = read_wav_float(wav)
    check(rate == SR and np.all(np.isfinite(x)), "the recording: %d Hz, finite" % rate)
    peak_db = 20.0 * np.log10(max(np.abs(x).max(), 1e-20))
    live_db, part = sounding_rms_db(x)
    ref_db, ref_part = sounding_rms_db(ref)
    ch_db = [10.0 * np.log10(np.mean(part[:, c] ** 2)) for c in (0, 1)]
    ref_ch_db = [10.0 * np.log10(np.mean(ref_part[:, c] ** 2)) for c in (0, 1)]
    print("live: peak %.2f dBFS, sounding %.2f s at %.2f dB (channels %.2f / %.2f)"
          % (peak_db, len(part) / SR, live_db, ch_db[0], ch_db[1]))
    print("render: peak %.2f dBFS, sounding %.2f s at %.2f dB (channels %.2f / %.2f)"
          % (20.0 * np.log10(np.abs(ref).max()), len(ref_part) / SR, ref_db, ref_ch_db[0],
             ref_ch_db[1]))
    check(peak_db <= PEAK_DBFS, "live peak %.2f dBFS <= %.1f" % (peak_db, PEAK_DBFS))
    check(abs(ch_db[0] - ch_db[1]) <= CHANNELS_DB, "live channels %.2f / %.2f dB within %.1f dB"
          % (ch_db[0], ch_db[1], CHANNELS_DB))
    check(abs(live_db - ref_db) <= LEVEL_DB, "live level %.2f dB within %.1f dB of the "
          "render's %.2f dB" % (live_db, LEVEL_DB, ref_db))
    bad = uitest.error_lines("\n".join(lines.printed))
    check(not bad, "no error lines from pd: %s" % bad)
    print("PASS")


if __name__ == "__main__":
    main()
