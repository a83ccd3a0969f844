"""Creation arguments of the abstractions, as a user types them: a bad one gets an error line
naming the abstraction and the argument, and is clamped or refused; it never reaches a vanilla
object inside as something else.

[ictus-out~ WIDTH] (docs/pd-osc.md, "The output stage"): a cosine into the left inlet only, so
the outlets read the width's a = (1 + W) / 2 and b = (1 - W) / 2. A width out of 0..1 is
clamped with the width's error line; a symbol leaves the default 1; extra arguments are
ignored, said so (they once reached the [clip 0 1] inside as its bounds: [ictus-out~ 0.2 9]
mixed with a = 5, b = -4, and no later width message could bring it back).

[ictus-receive PORT HOST] and its listen message (docs/pd-osc.md): a PORT that is not a whole
number in 0..65535 is refused by name and nothing listens ([netreceive] took 70000 as 70000 mod
65536 and bound port 4464 without a word, -5 and symbols said nothing or named [netreceive]); a
HOST that is not a symbol, or not one [netreceive] can listen on here (seeded random dotted
words like 1.2.3, addresses of the documentation networks, a name that does not resolve), falls
back to loopback, said so by ictus-receive (it was [netreceive]'s "listen failed: Cannot assign
requested address", and nothing listened); extra arguments are said. Read from the kernel's
table of UDP sockets (/proc/net/udp) while pd runs, in real time.

[ictus-drum] and [ictus-midi] take no arguments (their help): any given is an error naming the
abstraction and quoting it, and is ignored: the drum renders the same samples, the MIDI panel
sends the same notes (they were taken without a word).

[ictus-midifile CHANNEL] and its channel message (docs/midi.md): 0 or a whole 1..16; out of
range clamped, a symbol refused, extra arguments said, each by name ([ictus-midifile foo] left an
internal [f $1] that "couldn't create", and -3 or 99 were taken without a word).

ictus-render.pd's render-seconds (docs/pd-osc.md): outside 0.01..3600 s, or not a number, it is
refused by name and the length stays (1e9 had pd size its tables past what an int holds and hang
until the watchdog killed it; 0 and -1 wrote a WAV of one frame without a word); a symbol for
render-gain or render-pan, or for ictus-out~'s gain and width, is refused by name (they reached a
[t f f f] or a [clip] inside, whose errors named neither), and the render's report gives the gain
ictus-out~ applies (40 for render-gain 1e30, not 1e+30).

[ictus_timetag LATENCY] and its latency message (docs/pd-osc.md): a symbol is refused by name and
the latency stays (the object took one float argument: [ictus_timetag foo] could not be created,
and `latency foo` or a bare `latency` got Pd's "bad arguments"); out of 0..10000 ms it is clamped
to the nearest limit (1e30 was taken as 0).

[ictus-kit-drum N] (a kit's drum in ictus-render.pd and ictus-kit.pd, docs/pd-osc.md): N a whole
number 1..7; out of range or not whole it is clamped (drum min(7, max(1, int N))), a symbol or no
N takes drum 1, extra arguments are said, each naming ictus-kit-drum (9, foo and -1 were taken
without a word, and [ictus-kit-drum 9] played the hit lines of a drum 9 no kit has). NAME, the
prefix of its names (NAME-hit, NAME-N, throw~ NAME-l / -r): without it, or a number, it is
render-kit (the render's, what it was before it took a NAME), said. Checked by sound: the drum
the clamp names sounds for its hit line on the prefix's names, the bad number's does not.

    PYTHONPATH=python python3 tests/pdosc/test_abstraction_args.py --build build
"""
import argparse
import os
import random
import subprocess
import time

import numpy as np

from ictus_tools.checks import check, keep_going, failed
from ictus_tools.pdrun import (PD, PD_BATCH, PD_ENV, Patch, free_udp_port, make_workdir,
                               read_wav_float, recorder, run_pd)

SR, SECONDS, A = 48000, 0.2, 0.1


def out_args(build):
    # (arguments, width message sent at load or None, expected a and b, error lines expected)
    cases = [
        ("0.2", None, 0.2, []),
        ("0.2 9", None, 0.2, ["ictus-out~: takes one argument"]),
        ("0.2 9", "width 0", 0.0, ["ictus-out~: takes one argument"]),
        ("5", None, 1.0, ["ictus-out~: width must be in 0..1 (clamped) - got: 5"]),
        ("-1", None, 0.0, ["ictus-out~: width must be in 0..1 (clamped) - got: -1"]),
        ("foo", None, 1.0, ["ictus-out~: the argument WIDTH must be a number"]),
        ("foo", "width 0.5", 0.5, ["ictus-out~: the argument WIDTH must be a number"]),
        # a symbol for a number: said by name, the width or gain stays
        ("0.5", "width foo", 0.5, ["ictus-out~: width must be a number in 0..1 - got: foo"]),
        ("1", "gain foo", 1.0, ["ictus-out~: gain must be a number of dB - got: foo"]),
    ]
    p = Patch()
    osc = p.obj("osc~ 50")
    amp = p.obj("*~ %g" % A)
    p.connect(osc, 0, amp, 0)
    lb = p.obj("loadbang")
    tables = []
    for i, (arg, msg, _, _) in enumerate(cases):
        o = p.obj("ictus-out~ %s" % arg)
        p.connect(amp, 0, o, 0)
        if msg:
            m = p.msg(msg)
            p.connect(lb, 0, m, 0)
            p.connect(m, 0, o, 4)
        tables += [(o, 0, "l%d" % i), (o, 1, "r%d" % i)]
    work = make_workdir("ictus-pdosc-args-")
    wav = os.path.join(work, "out.wav")
    recorder(p, tables, SECONDS, SR, wav)
    rc, log = run_pd(p.text(), os.path.join(build, "ictus"), sr=SR, workdir=work)
    check(rc == 0, "pd ran (rc %d)" % rc)
    check("clip:" not in log and "trigger:" not in log,
          "no argument or message reaches a [clip] or [t f f f] inside: %s" %
          [l for l in log.splitlines() if "clip:" in l or "trigger:" in l])
    y, _ = read_wav_float(wav)
    peak = np.abs(y[len(y) // 2:]).max(axis=0)
    for i, (arg, msg, w, errors) in enumerate(cases):
        a, b = (1 + w) / 2, (1 - w) / 2
        what = "[ictus-out~ %s]%s" % (arg, " then %s" % msg if msg else "")
        check(abs(peak[2 * i] - A * a) < 1e-4 and abs(peak[2 * i + 1] - A * b) < 1e-4,
              "%s mixes with width %g: left %.5f (want %.5f), right %.5f (want %.5f)"
              % (what, w, peak[2 * i], A * a, peak[2 * i + 1], A * b))
        for e in errors:
            check(e in log, "%s: error line '%s'" % (what, e))
    lines = [l for l in log.splitlines() if l.startswith("error:")]
    want = sum(len(c[3]) for c in cases)
    check(len(lines) == want, "%d error lines, one per bad argument (got %d: %s)"
          % (want, len(lines), lines))


def bound_ports():
    """Every UDP port bound on this machine (/proc/net/udp)."""
    with open("/proc/net/udp") as f:
        rows = [line.split() for line in f.readlines()[1:]]
    return {int(r[1].split(":")[1], 16) for r in rows}


def receive_args(build):
    wrap, host5, extra, later, ok = (free_udp_port() for _ in range(5))
    rng = random.Random(20261203)
    # a.b.c is the IPv4 address a.b.0.c: a public unicast one (not loopback, a private or
    # link-local network, nor a multicast group, which netreceive joins)
    public = [a for a in range(1, 224) if a not in (10, 100, 127, 169, 172, 192)]
    bad_hosts = ["%d.%d.%d" % (rng.choice(public), rng.randint(0, 255), rng.randint(1, 254)),
                 "%s.%d" % (rng.choice(["192.0.2", "198.51.100", "203.0.113"]), rng.randint(1, 254)),
                 "nosuchhost.invalid"]
    host_line = ("ictus-receive: HOST must be an interface's name or address (127.0.0.1 or "
                 "0.0.0.0) - using 127.0.0.1 - got: ")
    # (arguments or listen message, the port it must bind or None, error lines expected)
    cases = [
        ("%d" % (wrap + 65536), None, ["ictus-receive: PORT must be a whole number in 0..65535 "
                                       "(0: not listening) - ignored - got: %d" % (wrap + 65536)]),
        ("-5", None, ["got: -5"]),
        ("foo", None, ["got: foo"]),
        ("1.5", None, ["got: 1.5"]),
        ("%d 5" % host5, host5, ["ictus-receive: HOST must be an interface's name or address "
                                 "(127.0.0.1 or 0.0.0.0) - using 127.0.0.1 - got: 5"]),
        ("%d 127.0.0.1 more" % extra, extra,
         ["ictus-receive: takes PORT and HOST - extra arguments ignored - got: more"]),
        ("listen %d" % (later + 65536), None, ["got: %d" % (later + 65536)]),
        ("listen", None, ["ictus-receive: listen needs a PORT in 0..65535 (0: stop)"]),
        ("%d" % ok, ok, []),
    ]
    for host in bad_hosts:
        port = free_udp_port()
        cases.append(("%d %s" % (port, host), port, [host_line + host]))
    port = free_udp_port()
    cases.append(("listen %d %s" % (port, bad_hosts[0]), port, [host_line + bad_hosts[0]]))
    p = Patch()
    lb = p.obj("loadbang")
    # [t b b]: the listen messages first, then a plain [netreceive] listens on `sentinel`,
    # bound once every listen message has been handled (the handshake below)
    sentinel = free_udp_port()
    order = p.obj("t b b")
    p.connect(lb, 0, order, 0)
    for arg, _, _ in cases:
        if arg.startswith("listen"):
            r = p.obj("ictus-receive")
            m = p.msg(arg)
            p.connect(order, 1, m, 0)
            p.connect(m, 0, r, 0)
        else:
            p.obj("ictus-receive %s" % arg)
    last = p.msg("listen %d 127.0.0.1" % sentinel)  # IPv4: read in /proc/net/udp
    p.connect(order, 0, last, 0)
    p.connect(last, 0, p.obj("netreceive -u"), 0)
    stop = p.obj("delay 20000")
    quit_msg = p.msg("\\; pd quit")
    p.connect(lb, 0, stop, 0)
    p.connect(stop, 0, quit_msg, 0)
    work = make_workdir("ictus-pdosc-args-")
    path = os.path.join(work, "receive.pd")
    with open(path, "w") as f:
        f.write(p.text())
    proc = subprocess.Popen([PD, "-nogui", "-nosound", "-stderr", "-path",
                             os.path.join(build, "ictus"), "-open", path],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            env=PD_ENV)
    # handshake: every receiver is created (the last one, `ok`, listens) and every listen
    # message handled (the sentinel listens) once both ports are bound; `ok` alone was
    # bound before the loadbang, and pd was ended before the listen messages' error lines
    deadline, ports = time.time() + 20, set()
    while time.time() < deadline and proc.poll() is None:
        ports = bound_ports()
        if ok in ports and sentinel in ports:
            break
        time.sleep(0.05)
    proc.terminate()
    log = proc.communicate(timeout=20)[0]
    check(ok in ports and sentinel in ports, "[ictus-receive %d] listens, and the listen "
          "messages were handled (the sentinel's %d is bound)" % (ok, sentinel))
    for arg, port, errors in cases:
        if port:
            check(port in ports, "[ictus-receive %s] listens on %d" % (arg, port))
        for e in errors:
            check(e in log, "[ictus-receive %s]: error line '%s'" % (arg, e))
    for p_ in (wrap, later):
        check(p_ not in ports, "nothing listens on %d (%d mod 65536)" % (p_, p_ + 65536))
    check("netreceive" not in log, "no line names the [netreceive] inside: %s"
          % [l for l in log.splitlines() if "netreceive" in l])


def midifile_args(build):
    cases = [("10", []), ("0", []),
             ("foo", ["ictus-midifile: CHANNEL must be a number 0..16 (unchanged) - got: foo"]),
             ("-3", ["ictus-midifile: CHANNEL must be 0 (every channel) or a whole number 1..16 "
                     "(clamped) - got: -3"]),
             ("99", ["(clamped) - got: 99"]), ("2.5", ["(clamped) - got: 2.5"]),
             ("1 2", ["ictus-midifile: takes one argument CHANNEL - extra arguments ignored - "
                      "got: 2"])]
    p = Patch()
    for arg, _ in cases:
        p.obj("ictus-midifile %s" % arg)
    r = p.obj("ictus-midifile")
    m = p.msg("channel 17")
    lb = p.obj("loadbang")
    p.connect(lb, 0, m, 0)
    p.connect(m, 0, r, 0)
    z = p.obj("sig~ 0")
    work = make_workdir("ictus-pdosc-args-")
    recorder(p, [(z, 0, "z")], 0.01, SR, os.path.join(work, "z.wav"))
    rc, log = run_pd(p.text(), os.path.join(build, "ictus"), sr=SR, workdir=work)
    check(rc == 0, "pd ran (rc %d)" % rc)
    for arg, errors in cases:
        for e in errors:
            check(e in log, "[ictus-midifile %s]: error line '%s'" % (arg, e))
    check("(clamped) - got: 17" in log, "channel 17 is clamped, said")
    lines = [l for l in log.splitlines() if l.startswith("error:")]
    check(len(lines) == 6 and all("ictus-midifile:" in l for l in lines),
          "one line per bad channel, each naming ictus-midifile: %s" % lines)


def render_seconds(build):
    work = make_workdir("ictus-pdosc-args-")
    events = os.path.join(work, "events.txt")
    with open(events, "w") as f:
        f.write("10 hit 1 0 0 3 0.3 0 10 0.01 1 0 0.01 0.05;\n")
    lib = os.path.join(build, "ictus")
    for bad, line in (("-1", "render-seconds must be in 0.01..3600 s (ignored - the length stays) - got: -1"),
                      ("0", "render-seconds must be in 0.01..3600 s (ignored - the length stays) - got: 0"),
                      ("1e9", "render-seconds must be in 0.01..3600 s (ignored - the length stays) - got: 1e+09"),
                      ("foo", "render-seconds must be a number of seconds (ignored) - got: foo")):
        wav = os.path.join(work, "render.wav")
        if os.path.exists(wav):
            os.remove(wav)
        cmd = PD_BATCH + ["-r", str(SR), "-path", lib, "-open",
                          os.path.join(lib, "ictus-render.pd"), "-send", "render-file " + events,
                          "-send", "render-out " + wav, "-send", "render-seconds 0.2", "-send",
                          "render-seconds " + bad]
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=60, env=PD_ENV)
            rc, log = proc.returncode, proc.stdout + proc.stderr
        except subprocess.TimeoutExpired:
            rc, log = None, "(no answer in 60 s)"
        check(rc == 0 and "error: ictus-render: " + line in log,
              "render-seconds %s is refused by name: %s" % (bad, log[-300:]))
        frames = len(read_wav_float(wav)[0]) if os.path.exists(wav) else 0
        check(frames == int(0.2 * SR), "... and the render keeps its 0.2 s: %d frames" % frames)
    # render-gain and render-pan: a symbol refused by name; the report gives the gain applied
    for send, line in (("render-gain foo", "error: ictus-render: render-gain must be a number of dB - "
                                           "got: foo"),
                       ("render-pan foo", "error: ictus-render: render-pan must be a number in 0..1 - "
                                          "got: foo"),
                       ("render-gain 1e30", "gain_db 40")):
        wav = os.path.join(work, "render.wav")
        cmd = PD_BATCH + ["-r", str(SR), "-path", lib, "-open",
                          os.path.join(lib, "ictus-render.pd"), "-send", "render-file " + events,
                          "-send", "render-out " + wav, "-send", "render-seconds 0.2", "-send",
                          send]
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=60, env=PD_ENV)
        log = proc.stdout + proc.stderr
        check(proc.returncode == 0 and line in log and "trigger:" not in log and "clip:" not in log,
              "%s: '%s' and nothing from a vanilla object inside: %s" % (send, line, log[-300:]))


def timetag_args(build):
    cases = [("foo", ["ictus_timetag: creation argument: the latency (ms) must be a number, got "
                      "'foo'; it stays 0 ms"], 0),
             ("2e4", ["ictus_timetag: latency must be in [0, 10000] ms, got 20000; using 10000"],
              10000),
             ("5 6", ["ictus_timetag: creation argument takes one number, the latency (ms); extra "
                      "arguments ignored"], 5),
             ("7", [], 7)]
    p = Patch()
    info = p.obj("print info")
    lb = p.obj("loadbang")
    st = p.msg("status")
    p.connect(lb, 0, st, 0)
    for arg, _, _ in cases:
        t = p.obj("ictus_timetag %s" % arg)
        p.connect(st, 0, t, 0)
        p.connect(t, 2, info, 0)
    # the messages, on one more
    t = p.obj("ictus_timetag")
    m = p.msg("latency foo \\, latency \\, latency 1e30 \\, status \\, latency -3 \\, status "
              "\\, expect \\, expect 5 ii \\, expect /a ii jj \\, expect /ictus/x ii")
    p.connect(lb, 0, m, 0)
    p.connect(m, 0, t, 0)
    p.connect(t, 2, p.obj("print info2"), 0)
    z = p.obj("sig~ 0")
    work = make_workdir("ictus-pdosc-args-")
    recorder(p, [(z, 0, "z")], 0.01, SR, os.path.join(work, "z.wav"))
    rc, log = run_pd(p.text(), os.path.join(build, "ictus"), sr=SR, workdir=work)
    check(rc == 0 and "couldn't create" not in log and "bad arguments" not in log,
          "every ictus_timetag is created and takes its messages: %s" % log[-400:])
    for arg, errors, latency in cases:
        for e in errors:
            check(e in log, "[ictus_timetag %s]: error line '%s'" % (arg, e))
    statuses = [l.split()[-1] for l in log.splitlines() if l.startswith("info: status")]
    check(sorted(statuses, key=float) == ["0", "5", "7", "10000"],
          "the latencies in use: 0, 5, 7, 10000 ms (status: %s)" % statuses)
    statuses = [l.split()[-1] for l in log.splitlines() if l.startswith("info2: status")]
    for e in ("ictus_timetag: latency: the latency (ms) must be a number, got 'foo'; it stays 0 ms",
              "ictus_timetag: latency: missing the latency (ms)",
              "ictus_timetag: latency must be in [0, 10000] ms, got 1e+30; using 10000",
              "ictus_timetag: latency must be in [0, 10000] ms, got -3; using 0"):
        check(e in log, "latency messages: '%s'" % e)
    # expect with no address, a number for it, or three words: said by name, three times
    check(log.count("ictus_timetag: expect needs ADDRESS and TAGS, two symbols") == 3,
          "a bad expect is said by name, three times: %s" % log[-600:])
    check(statuses == ["10000", "0"], "latency 1e30 sets 10000, -3 sets 0 (%s)" % statuses)


def kit_drum_args(build):
    def clamped(arg):  # the drum a bad N is clamped to, computed here
        try:
            return min(7, max(1, int(float(arg.split()[0]))))
        except (ValueError, IndexError):
            return 1
    no_name = ("ictus-kit-drum: takes N NAME (NAME-hit NAME-1..7 NAME-l NAME-r) - no NAME - "
               "using: render-kit")
    # (arguments, error lines expected, the names' prefix it must use)
    cases = [("9 render-kit",
              ["ictus-kit-drum: N must be a whole number 1..7 (clamped) - got: 9"], "render-kit"),
             ("-1 kitx", ["ictus-kit-drum: N must be a whole number 1..7 (clamped) - got: -1"],
              "kitx"),
             ("2.5 render-kit",
              ["ictus-kit-drum: N must be a whole number 1..7 (clamped) - got: 2.5"], "render-kit"),
             ("foo render-kit", ["ictus-kit-drum: N must be a number 1..7 - using 1 - got: foo"],
              "render-kit"),
             ("", [no_name, "ictus-kit-drum: takes N (the kit's drum 1..7) - using: 1"],
              "render-kit"),
             ("3", [no_name], "render-kit"),
             ("3 4", ["ictus-kit-drum: NAME must be a symbol (the kit's name) - using render-kit"
                      " - got: 4"], "render-kit"),
             ("3 kitx 4", ["ictus-kit-drum: takes two arguments N NAME - extra arguments ignored"
                           " - got: 4"], "kitx"),
             ("5 render-kit", [], "render-kit"),
             ("6 kitx", [], "kitx")]
    work = make_workdir("ictus-pdosc-args-")
    for arg, errors, prefix in cases:
        want = clamped(arg)
        other = 9 if arg.startswith("9") else (want % 7) + 1  # a drum this one must not play
        peaks = []
        for drum in (want, other):
            p = Patch()
            p.obj("ictus-kit-drum %s" % arg)
            p.obj("r %s-%d" % (prefix, drum))  # a receiver for drum 9's messages too
            catch = p.obj("catch~ %s-l" % prefix)
            wav = os.path.join(work, "kit-%d.wav" % drum)
            trig = recorder(p, [(catch, 0, "k")], SECONDS, SR, wav)
            m = p.msg("\\; %s-%d dsp 1 \\; %s-hit 1 %d 0 3 0.3 0 10 0.01 1 0 0"
                      % (prefix, drum, prefix, drum))
            p.connect(trig, 2, m, 0)
            rc, log = run_pd(p.text(), os.path.join(build, "ictus"), sr=SR, workdir=work)
            check(rc == 0, "pd ran (rc %d)" % rc)
            peaks.append(float(np.abs(read_wav_float(wav)[0]).max()))
            lines = [l for l in log.splitlines() if l.startswith("error:")]
            check(lines == ["error: " + e for e in errors],
                  "[ictus-kit-drum %s]: error lines %s (got %s)" % (arg, errors, lines))
        check(peaks[0] > 1e-4 and peaks[1] == 0.0,
              "[ictus-kit-drum %s] plays drum %d of %s (peak %.3g) and not drum %d (peak %.3g)"
              % (arg, want, prefix, peaks[0], other, peaks[1]))


def drum_midi_args(build):
    rng = random.Random(20261203)
    drum_args = ["5", "%d" % rng.randint(-9, 99), rng.choice(["foo", "snare", "Tom"]),
                 "%g %s" % (rng.uniform(-5, 5), rng.choice(["a", "b"]))]
    midi_args = ["20", "%d" % rng.randint(1, 16), rng.choice(["on", "in", "x"]) + " 3"]
    p = Patch()
    lb = p.obj("loadbang")
    tables = []
    for i, arg in enumerate([""] + drum_args):
        d = p.obj("ictus-drum %s" % arg)
        m = p.msg("1 2 0.3 0")
        p.connect(lb, 0, m, 0)
        p.connect(m, 0, d, 0)
        tables.append((d, 0, "d%d" % i))
    for i, arg in enumerate([""] + midi_args):
        panel = p.obj("ictus-midi %s" % arg)
        m = p.msg("on 1 \\, 1 2 0.3 0")
        p.connect(lb, 0, m, 0)
        p.connect(m, 0, panel, 0)
        p.connect(panel, 0, p.obj("print midi%d" % i), 0)
    work = make_workdir("ictus-pdosc-args-")
    wav = os.path.join(work, "drums.wav")
    recorder(p, tables, SECONDS, SR, wav)
    rc, log = run_pd(p.text(), os.path.join(build, "ictus"), sr=SR, workdir=work)
    check(rc == 0, "pd ran (rc %d)" % rc)
    want = ["error: ictus-drum: takes no arguments - ignored - got: %s" % a for a in drum_args]
    want += ["error: ictus-midi: takes no arguments - ignored - got: %s" % a for a in midi_args]
    lines = [l for l in log.splitlines() if l.startswith("error:")]
    check(sorted(lines) == sorted(want), "one error line per abstraction given arguments, quoting "
          "them: %s (want %s)" % (lines, want))
    y, _ = read_wav_float(wav)
    check(np.abs(y[:, 0]).max() > 1e-4, "[ictus-drum] sounds")
    for i, arg in enumerate(drum_args):
        check(np.array_equal(y[:, i + 1], y[:, 0]),
              "[ictus-drum %s] renders [ictus-drum]'s samples: the argument is ignored" % arg)
    notes = [sorted(l.split(":", 1)[1] for l in log.splitlines() if l.startswith("midi%d:" % i))
             for i in range(len(midi_args) + 1)]
    check(len(notes[0]) == 1, "[ictus-midi] sends a note for the strike: %s" % notes[0])
    for i, arg in enumerate(midi_args):
        check(notes[i + 1] == notes[0],
              "[ictus-midi %s] sends [ictus-midi]'s note %s: %s" % (arg, notes[0], notes[i + 1]))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    build = os.path.abspath(ap.parse_args().build)
    keep_going()
    out_args(build)
    receive_args(build)
    midifile_args(build)
    render_seconds(build)
    timetag_args(build)
    kit_drum_args(build)
    drum_midi_args(build)
    if failed():
        raise SystemExit(1)
    print("ok")


if __name__ == "__main__":
    main()
