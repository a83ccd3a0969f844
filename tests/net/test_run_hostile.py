"""`ictusd run` under a hostile client, on loopback (docs/osc.md, "Limits"): the real daemon,
driven by raw OSC (ictus_tools.oscpacket), strikes received by a Python listener, strikes.csv
read back. Every wait is a handshake (/ictus/ping answered, a process ended) with a deadline.

  --case log    stderr a pipe nobody reads while /ictus/drum/radius floods the daemon during
                the default score: the performance goes on (>= 30 of its 32 strikes in
                strikes.csv) and the process ends at --duration; with stderr a file, the lines
                written stay within the log's rate (base/async_log.hpp).
  --case stop   a score of 11,000 notes (--notes), 100 seeded play/stop pairs (fewer where
                planning is slow, to fill --pair-seconds; the stop at any point of the
                planning), ending in stop: no strike after the last stop, status stopped.
  --case grip   /ictus/grip toggled 20 times a second during the default score: every onset
                received has its /ictus/strike/end and its strikes.csv row, and the reverse.
  --case score  10^6 score statements over OSC (nested `repeat 1`): refused past the
                documented cap with /ictus/error, the daemon's RSS (from /proc) stays within
                the documented bound, and the default score played meanwhile loses no strike;
                the run stopped by SIGTERM once both are over.
"""
import argparse
import os
import random
import socket
import struct
import subprocess
import sys
import tempfile
import threading
import time

from ictus_tools import oscpacket as osc
from ictus_tools.pdrun import free_udp_port

DEFAULT_SCORE_STRIKES = 32  # the built-in score's notes (score.cpp, default_score_text)
# Wall-clock deadlines allow a daemon four times slower than real time (a sanitizer build).
SLOW = 4.0
# docs/osc.md, "Limits": the log writes at most 10 lines a second plus two reports.
LOG_LINES_PER_SECOND = 12
MAX_PENDING_STATEMENTS = 10000  # Performance::kMaxPendingStatements
RSS_BOUND_MB = 16  # docs/osc.md: 10000 statements of ~250 bytes, twice (a play copies them)


def fail(text):
    print("FAIL: " + text)
    sys.exit(1)


def parse_strings(data, pos):
    end = data.index(b"\0", pos)
    text = data[pos:end].decode("latin-1")
    return text, (end + 4) & ~3


def parse_message(data):
    """(address, [args]) of an OSC message (i, f, s only)."""
    address, pos = parse_strings(data, 0)
    tags, pos = parse_strings(data, pos)
    args = []
    for t in tags[1:]:
        if t == "i":
            args.append(struct.unpack(">i", data[pos:pos + 4])[0])
            pos += 4
        elif t == "f":
            args.append(struct.unpack(">f", data[pos:pos + 4])[0])
            pos += 4
        elif t == "s":
            text, pos = parse_strings(data, pos)
            args.append(text)
        else:
            return address, None
    return address, args


def messages(packet):
    if packet.startswith(b"#bundle\0"):
        pos = 16
        while pos + 4 <= len(packet):
            size = struct.unpack(">i", packet[pos:pos + 4])[0]
            yield from messages(packet[pos + 4:pos + 4 + size])
            pos += 4 + size
    else:
        yield parse_message(packet)


class Listener:
    """The daemon's target: strikes and their ends as they arrive (seq -> arrival time)."""

    def __init__(self):
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 20)
        self.sock.bind(("127.0.0.1", 0))
        self.sock.settimeout(0.1)
        self.port = self.sock.getsockname()[1]
        self.onsets, self.ends = {}, {}
        self.running = True
        self.thread = threading.Thread(target=self.loop, daemon=True)
        self.thread.start()

    def loop(self):
        while True:
            try:
                packet = self.sock.recv(65536)
            except socket.timeout:
                if not self.running:
                    return  # closed, and nothing left in the socket's buffer
                continue
            now = time.monotonic()
            for address, args in messages(packet):
                if address == "/ictus/strike" and args:
                    self.onsets.setdefault(args[0], now)
                elif address == "/ictus/strike/end" and args:
                    self.ends.setdefault(args[0], now)

    def close(self):
        """Stops once the datagrams already delivered are read (a loopback send is in the
        buffer when sendto returns: the daemon's, once it has ended, all are)."""
        self.running = False
        self.thread.join()
        self.sock.close()


class Daemon:
    def __init__(self, ictusd, args, out_dir, listener, stderr):
        self.port = free_udp_port()
        self.out_dir = out_dir
        cmd = [ictusd, "run", "--port", str(self.port), "--pose-rate", "0", "--out", out_dir,
               "--target", "osc.udp://127.0.0.1:%d" % listener.port] + args
        self.proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=stderr)
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 20)
        self.sock.bind(("127.0.0.1", 0))
        self.errors = []

    def send(self, address, tags="", *args):
        self.sock.sendto(osc.message(address, tags, *args), ("127.0.0.1", self.port))

    def replies(self, timeout):
        """Messages received within `timeout` s (the first may wait that long)."""
        self.sock.settimeout(timeout)
        try:
            while True:
                address, args = parse_message(self.sock.recv(65536))
                if address == "/ictus/error":
                    self.errors.append(args)
                yield address, args
                self.sock.settimeout(0)
        except (socket.timeout, BlockingIOError):
            return

    def handshake(self, deadline_s=30.0):
        """Pings until the daemon answers (it is listening, everything sent before is handled)."""
        end = time.monotonic() + deadline_s
        while time.monotonic() < end:
            if self.proc.poll() is not None:
                fail("ictusd ended (exit %s) before answering /ictus/ping" % self.proc.returncode)
            self.send("/ictus/ping")
            for address, _ in self.replies(0.2):
                if address == "/ictus/pong":
                    return
        fail("no /ictus/pong within %.0f s" % deadline_s)

    def status(self):
        """/ictus/status: (time_s, playing, ...)."""
        for _ in range(50):
            self.send("/ictus/status")
            for address, args in self.replies(0.2):
                if address == "/ictus/reply" and args and args[0] == "/ictus/status":
                    return args[1:]
        fail("no answer to /ictus/status")

    def wait(self, deadline_s):
        try:
            return self.proc.wait(timeout=deadline_s)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
            fail("ictusd still running after %.0f s (its --duration ended before)" % deadline_s)

    def rss_kb(self):
        with open("/proc/%d/status" % self.proc.pid) as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1])
        return 0

    def strike_rows(self):
        with open(os.path.join(self.out_dir, "strikes.csv")) as f:
            lines = f.read().splitlines()
        header = lines[0].split(",")
        rows = [dict(zip(header, line.split(","))) for line in lines[1:]]
        return rows


def case_log(ictusd, workdir):
    """stderr unread: the physics goes on and the run ends; stderr a file: lines bounded.
    The two daemons run side by side, flooded by the same loop."""
    duration = 20.0
    runs = []
    for kind in ("pipe", "file"):
        listener = Listener()
        out = os.path.join(workdir, "log-" + kind)
        err_path = os.path.join(workdir, "log-%s.stderr" % kind)
        stderr = subprocess.PIPE if kind == "pipe" else open(err_path, "wb")
        d = Daemon(ictusd, ["--autoplay", "--duration", str(duration)], out, listener, stderr)
        runs.append((kind, listener, err_path, stderr, d))
    for _, _, _, _, d in runs:
        d.handshake()
    start = time.monotonic()
    # ~3 s of drum changes, up to 20,000 a second to each (each past the planner's 64 is
    # refused).
    sent = 0
    while time.monotonic() - start < 3.0:
        for _ in range(200):
            for _, _, _, _, d in runs:
                d.send("/ictus/drum/radius", "f", 0.178 if sent % 2 else 0.18)
            sent += 1
        time.sleep(0.01)
    codes = [d.wait(SLOW * duration + 30.0) for _, _, _, _, d in runs]
    for (kind, listener, err_path, stderr, d), code in zip(runs, codes):
        listener.close()
        elapsed = time.monotonic() - start
        rows = d.strike_rows()
        print("stderr %s: %d radius changes sent; exit %d after %.1f s; %d strikes.csv rows"
              % (kind, sent, code, elapsed, len(rows)))
        if code != 0:
            fail("exit %d" % code)
        if len(rows) < DEFAULT_SCORE_STRIKES - 2:
            fail("%d of %d strikes (>= 30 expected)" % (len(rows), DEFAULT_SCORE_STRIKES))
        if kind == "file":
            stderr.close()
            with open(err_path, "rb") as f:
                lines = f.read().decode("latin-1").splitlines()
            # The log's rate over the run, plus the start-up lines and the last report.
            bound = LOG_LINES_PER_SECOND * (duration + 2.0) + 10
            print("stderr file: %d lines (bound %d)" % (len(lines), bound))
            if len(lines) > bound:
                fail("%d lines written to stderr (bound %d)" % (len(lines), bound))
            if not any("repeated" in l or "not shown" in l for l in lines):
                fail("the flood's refusals were neither collapsed nor counted")
        else:
            d.proc.stderr.close()


def write_big_score(path, notes):
    with open(path, "w") as f:
        f.write("tempo 200\n")
        for i in range(notes // 2):
            f.write("R 1/4, L 1/4\n")


def case_stop(ictusd, workdir, notes=11000, pair_seconds=120.0):
    """100 play/stop pairs (fewer where planning is slow) on an 11,000-note score, the stop at
    any point of planning."""
    score = os.path.join(workdir, "big.txt")
    write_big_score(score, notes)
    listener = Listener()
    d = Daemon(ictusd, ["--score", score, "--duration", "600"], os.path.join(workdir, "stop"),
               listener, subprocess.DEVNULL)
    d.handshake()
    # How long a play takes to plan here: from the play to the status saying playing.
    asked = time.monotonic()
    d.send("/ictus/play")
    while d.status()[1] != 1:
        if time.monotonic() - asked > 30.0:
            fail("the score did not start within 30 s of /ictus/play")
    plan_s = time.monotonic() - asked
    d.send("/ictus/stop")
    d.handshake()
    print("a play of %d notes planned in %.2f s" % (notes, plan_s))
    rng = random.Random(2911)
    # 100 pairs, fewer where planning is slow (a sanitizer build: ~0.75 plan_s a pair), so
    # that the pairs take at most pair_seconds (~2 minutes); at least 10.
    pairs = max(10, min(100, int(pair_seconds / (0.75 * plan_s))))
    print("%d play/stop pairs" % pairs)
    for pair in range(pairs):
        d.send("/ictus/play")
        # The stop at any point of the planning, or just after it; the last one at once.
        time.sleep(rng.uniform(0.0, 1.5 * plan_s) if pair < pairs - 1 else 0.0)
        d.send("/ictus/stop")
    d.handshake()  # the last stop is handled
    stopped_at = time.monotonic()
    # The plans asked for may take up to 100 x 0.3 s to come back: watch 3 s, then the status.
    watch_until = stopped_at + 3.0
    while time.monotonic() < watch_until:
        list(d.replies(0.1))
    status = d.status()
    late = sorted(seq for seq, t in listener.onsets.items() if t > stopped_at + 0.05)
    print("%d onsets in all, %d after the last stop; status playing=%d"
          % (len(listener.onsets), len(late), status[1]))
    d.proc.terminate()
    d.wait(20.0)
    listener.close()
    if late:
        fail("strikes after the last stop: seq %s" % late[:10])
    if status[1] != 0:
        fail("playing after %d play/stop pairs ending in stop" % pairs)


def case_grip(ictusd, workdir):
    """Grip toggled 20 times a simulated second: onsets, ends and rows are the same strikes."""
    duration = 20.0
    listener = Listener()
    d = Daemon(ictusd, ["--autoplay", "--duration", str(duration)], os.path.join(workdir, "grip"),
               listener, subprocess.DEVNULL)
    d.handshake()
    # The daemon's pace (simulated over wall-clock seconds, from its status over half a
    # second): a daemon slower than real time (a sanitizer build) gets the changes as densely
    # in simulated time as a real-time one.
    w0, s0 = time.monotonic(), float(d.status()[0])
    while time.monotonic() - w0 < 0.5:
        list(d.replies(0.1))
    pace = (float(d.status()[0]) - s0) / (time.monotonic() - w0)
    pace = min(1.0, max(0.05, pace))
    print("the daemon runs at %.2f x real time" % pace)
    start = t_flood = time.monotonic()
    k = k0 = 0
    sim = 0.0
    while d.proc.poll() is None and time.monotonic() - t_flood < SLOW * duration + 30.0:
        d.send("/ictus/grip", "s", "german" if k % 2 == 0 else "french")
        k += 1
        list(d.replies(0.0))
        # the pace again, from the start (a daemon may slow down as it goes), while the
        # daemon is surely still there to answer
        if k % 20 == 0 and s0 + sim < duration - 3.0:
            sim = float(d.status()[0]) - s0
            pace = min(1.0, max(0.05, sim / (time.monotonic() - w0)))
            start, k0 = time.monotonic(), k
        time.sleep(max(0.0, start + 0.05 * (k - k0) / pace - time.monotonic()))
    code = d.wait(20.0)
    listener.close()
    rows = {int(r["seq"]) for r in d.strike_rows()}
    onsets, ends = set(listener.onsets), set(listener.ends)
    print("%d grip changes; %d onsets, %d ends, %d rows; exit %d"
          % (k, len(onsets), len(ends), len(rows), code))
    if code != 0:
        fail("exit %d" % code)
    if onsets - ends or onsets - rows:
        fail("onsets without end: %s, without row: %s"
             % (sorted(onsets - ends), sorted(onsets - rows)))
    if ends - onsets or rows - onsets:
        fail("ends without onset: %s, rows without onset: %s"
             % (sorted(ends - onsets), sorted(rows - onsets)))
    if len(rows) < DEFAULT_SCORE_STRIKES // 2:
        fail("only %d strikes" % len(rows))


def sanitized(ictusd):
    """Whether ictusd is built with AddressSanitizer (its runtime's entry point is named)."""
    with open(ictusd, "rb") as f:
        return b"__asan_init" in f.read()


def case_score(ictusd, workdir):
    """10^6 nested `repeat 1` statements during the default score; the run ends once the
    flood is handled and the score played out (status not playing, every onset ended), by
    SIGTERM (exit 130, the run's clean end: strikes.csv written as at --duration), not at a
    --duration long enough for the slowest flood."""
    listener = Listener()
    d = Daemon(ictusd, ["--autoplay"], os.path.join(workdir, "score"), listener,
               subprocess.DEVNULL)
    d.handshake()
    rss0 = d.rss_kb()
    peak = rss0
    start = time.monotonic()
    total = 1000000
    packet = osc.message("/ictus/score", "s", "repeat 1")
    errors = 0
    for batch in range(total // 500):
        if time.monotonic() - start > 300.0:
            d.proc.kill()
            fail("10^6 statements not handled within 300 s (%d batches)" % batch)
        for _ in range(500):
            d.sock.sendto(packet, ("127.0.0.1", d.port))
        d.send("/ictus/ping")  # flow control: the batch is handled when the pong is back
        for address, args in d.replies(2.0):
            errors += address == "/ictus/error" and "statements are waiting" in args[1]
            if address == "/ictus/pong":
                break
        if batch % 100 == 0:
            peak = max(peak, d.rss_kb())
    peak = max(peak, d.rss_kb())
    sent_s = time.monotonic() - start
    # The default score (~15 s) played out: polled with a deadline for a daemon SLOW times
    # slower than real time, then every onset received has its end (a strike's end follows
    # its release).
    deadline = time.monotonic() + SLOW * 15.0 + 30.0
    while d.status()[1] != 0 or set(listener.onsets) - set(listener.ends):
        if time.monotonic() > deadline:
            d.proc.kill()
            fail("the default score still playing %.0f s after the flood" % (SLOW * 15.0 + 30.0))
        list(d.replies(0.2))
    d.proc.terminate()
    code = d.wait(30.0)
    listener.close()
    rows = d.strike_rows()
    growth_mb = (peak - rss0) / 1024.0
    print("%d statements in %.1f s; %d refusals answered; RSS %.1f -> %.1f MB (+%.1f); "
          "%d strikes; exit %d" % (total, sent_s, errors, rss0 / 1024.0, peak / 1024.0, growth_mb,
                                   len(rows), code))
    if code != 130:
        fail("exit %d after SIGTERM (130 expected)" % code)
    if errors == 0:
        fail("no /ictus/error refusing statements past the cap")
    if sanitized(ictusd):
        # the sanitizer's allocator holds freed memory in quarantine (256 MB by default):
        # its RSS says nothing of the daemon's own bound
        print("a sanitizer build: RSS growth not held to the bound")
    elif growth_mb > RSS_BOUND_MB:
        fail("RSS grew by %.1f MB (bound %d MB)" % (growth_mb, RSS_BOUND_MB))
    if len(rows) < DEFAULT_SCORE_STRIKES - 2:
        fail("%d of %d strikes during the flood" % (len(rows), DEFAULT_SCORE_STRIKES))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--ictusd", required=True)
    ap.add_argument("--case", required=True, choices=["log", "stop", "grip", "score"])
    ap.add_argument("--workdir")
    ap.add_argument("--notes", type=int, default=11000, help="--case stop: the score's notes")
    ap.add_argument("--pair-seconds", type=float, default=120.0,
                    help="--case stop: the time the play/stop pairs may take (at most 100)")
    a = ap.parse_args()
    workdir = a.workdir or tempfile.mkdtemp(prefix="ictus-hostile-")
    os.makedirs(workdir, exist_ok=True)
    if a.case == "stop":
        case_stop(a.ictusd, workdir, a.notes, a.pair_seconds)
    else:
        {"log": case_log, "grip": case_grip, "score": case_score}[a.case](a.ictusd, workdir)
    print("PASS")


if __name__ == "__main__":
    main()
