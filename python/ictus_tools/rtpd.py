"""Runs the real pd binary in real time (no -batch: Pd's clock follows the
system clock) with [ictus-receive PORT], and listens to what the patch reports
back over UDP (FUDI text, [netsend -u]):

    tick <logical_ms>;            every 2 ms of logical time ([metro 2] + [timer])
    fire <logical_ms> <strike>;   when a strike comes out of ictus-receive
    probe <logical_ms> <k>;       echo of a `probe k` sent to the FUDI port
                                  (`quit` there ends pd: see quit_pd)
    plain <logical_ms> <seq>;     (optional) a strike parsed by a bare [oscparse]
    pose ... / reply ... / info ...;   the other outlets

Each report is stamped with CLOCK_REALTIME on arrival by the kernel
(SO_TIMESTAMPNS: when the datagram reached the socket, not when this Python
thread woke up to read it, which on a loaded machine was milliseconds later
and moved the mapping below by as much). The smallest
(arrival - start of the report's scheduler tick) over the ticks maps logical
time to wall time, independently of [ictus_timetag] (another process, another
clock read, another path): Pd starts a tick no earlier than its wall time, so
the smallest observed difference is the mapping (plus the loopback's few tens
of us)."""
import math
import os
import re
import socket
import struct
import subprocess
import threading
import time

from ictus_tools.checks import check, inconclusive
from ictus_tools.oscpacket import now
from ictus_tools.pdrun import PD, PD_ENV, Patch, free_udp_port, make_workdir  # noqa: F401


# Linux's SO_TIMESTAMPNS (= SCM_TIMESTAMPNS): the kernel's CLOCK_REALTIME arrival
# stamp of each datagram, as a struct timespec in the ancillary data.
SO_TIMESTAMPNS = getattr(socket, "SO_TIMESTAMPNS", 35)
# Linux's SO_RCVBUFFORCE (root may exceed net.core.rmem_max).
SO_RCVBUFFORCE = getattr(socket, "SO_RCVBUFFORCE", 33)
# The reports' receive buffer: pd's ticks alone are 500 datagrams a second (about 1 KB of
# buffer each, with the kernel's overhead), which the default 208 KB holds for 0.4 s of a
# stalled reader. 8 MB holds 16 s.
LISTENER_BUFFER = 8 << 20


class Listener:
    """UDP socket that stamps every datagram with the wall clock on arrival
    (the kernel's stamp where it gives one, else the clock when read). Its
    receive buffer is as large as the system lets it be, and lost() counts the
    datagrams the kernel dropped on it all the same (a reader starved past what
    the buffer holds): a test calls require_intact() before it judges what is
    missing, since a lost report says nothing about pd."""

    def __init__(self):
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        for opt in (SO_RCVBUFFORCE, socket.SO_RCVBUF):
            try:
                self.sock.setsockopt(socket.SOL_SOCKET, opt, LISTENER_BUFFER)
                break
            except OSError:
                continue  # not root: SO_RCVBUF, capped at net.core.rmem_max
        # Linux reports twice the size set (the other half is its bookkeeping, socket(7)):
        # the half is what holds datagrams' worth, and what was asked for.
        self.buffer_bytes = self.sock.getsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF) // 2
        try:
            self.sock.setsockopt(socket.SOL_SOCKET, SO_TIMESTAMPNS, 1)
        except OSError:
            pass  # no kernel stamps: read-time stamps
        self.dropped = 0  # lost() once closed
        self._parsed = 0  # items parsed into _records so far (records())
        self._records = []
        self.sock.bind(("127.0.0.1", 0))
        self.sock.settimeout(0.2)
        self.port = self.sock.getsockname()[1]
        self.items = []  # (wall_s, bytes)
        self.lock = threading.Lock()
        self.running = True
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self):
        while self.running:
            try:
                data, ancillary, _, _ = self.sock.recvmsg(65536, 64)
            except socket.timeout:
                continue
            except OSError:
                return
            t = now()
            for level, kind, payload in ancillary:
                if level == socket.SOL_SOCKET and kind == SO_TIMESTAMPNS and len(payload) >= 16:
                    sec, nsec = struct.unpack("qq", payload[:16])
                    t = sec + nsec * 1e-9
            with self.lock:
                self.items.append((t, data))

    def snapshot(self):
        with self.lock:
            return list(self.items)

    def records(self):
        """fudi_records() of every datagram so far, each parsed once: a test that polls
        its reports every 20 ms would otherwise parse all of them each time, thousands of
        ticks, holding the interpreter lock that the reading thread waits for."""
        with self.lock:
            new = self.items[self._parsed:]
            self._parsed = len(self.items)
        self._records.extend(fudi_records(new))
        return list(self._records)

    def lost(self):
        """Datagrams the kernel dropped on this socket so far, from /proc/net/udp (0 where
        there is none). After close(): the count at closing."""
        if self.sock.fileno() < 0:
            return self.dropped
        try:
            with open("/proc/net/udp") as f:
                for line in f.readlines()[1:]:
                    fields = line.split()
                    if fields[1] == "0100007F:%04X" % self.port:
                        return int(fields[-1])
        except (OSError, IndexError, ValueError):
            pass
        return 0

    def require_intact(self):
        """Ends the test as inconclusive (checks.inconclusive: CTest's command runs it again)
        when the kernel dropped any report: a report this process failed to read says
        nothing of pd, and whatever the test finds missing may be one of them."""
        n = self.lost()
        if n:
            inconclusive("this test's listener lost %d of pd's reports (the kernel dropped them: "
                         "its reader was starved past a %d KB buffer); pd is not judged"
                         % (n, self.buffer_bytes // 1024))

    def close(self):
        self.running = False
        self.thread.join()
        self.dropped = self.lost()
        self.sock.close()


def fudi_records(items):
    """(wall_s, [atoms]) per FUDI message; numbers as floats."""
    out = []
    for t, data in items:
        for msg in re.split(r"(?<!\\);", data.decode(errors="replace")):
            # FUDI escapes spaces, commas and semicolons inside a symbol
            words = [re.sub(r"\\(.)", r"\1", w) for w in re.split(r"(?<!\\)\s+", msg.strip())
                     if w]
            if not words:
                continue
            atoms = []
            for w in words:
                try:
                    atoms.append(float(w))
                except ValueError:
                    atoms.append(w)
            out.append((t, atoms))
    return out


def build_patch(build, pd_port, report_port, seconds, ctl_port=None, plain_port=None,
                control_msgs=(), listen_later=False, fudi_in_port=None, ballast=0):
    """The real-time test patch (see the module doc). pd quits after `seconds`: a
    deadline only, for a test that ends pd by handshake (quit_pd, with
    fudi_in_port) once it has what it waits for. control_msgs go into
    ictus-receive's inlet at 300 ms (after 'connect localhost ctl_port'). With
    listen_later, [ictus-receive] starts without a port and gets 'listen
    pd_port' at 300 ms."""
    p = Patch(declare="-path %s/ictus" % build)
    recv = p.obj("ictus-receive" if listen_later else "ictus-receive %d" % pd_port)
    lb = p.obj("loadbang")
    t = p.obj("t b b b b")
    p.connect(lb, 0, t, 0)
    net = p.obj("netsend -u")
    conn = p.msg("connect localhost %d" % report_port)
    p.connect(t, 3, conn, 0)
    p.connect(conn, 0, net, 0)
    timer = p.obj("timer")
    p.connect(t, 2, timer, 0)

    def report(src, outlet, prefix):
        lp = p.obj("list prepend %s" % prefix)
        ls = p.obj("list prepend send")
        lt = p.obj("list trim")
        p.connect(src, outlet, lp, 0)
        p.connect(lp, 0, ls, 0)
        p.connect(ls, 0, lt, 0)
        p.connect(lt, 0, net, 0)

    def stamped(src, outlet, prefix):
        """report '<prefix> <logical_ms> <the message>' when src outputs."""
        tba = p.obj("t b a")
        app = p.obj("list append")
        tim = p.obj("timer")
        p.connect(t, 2, tim, 0)
        p.connect(src, outlet, tba, 0)
        p.connect(tba, 1, app, 1)
        p.connect(tba, 0, tim, 1)
        p.connect(tim, 0, app, 0)
        report(app, 0, prefix)

    metro = p.obj("metro 2")
    p.connect(t, 1, metro, 0)
    p.connect(metro, 0, timer, 1)
    report(timer, 0, "tick")
    stamped(recv, 0, "fire")
    report(recv, 1, "pose")
    report(recv, 2, "reply")
    report(recv, 3, "info")
    if plain_port:
        # a bare [oscparse] path: strikes fire on arrival, timetag ignored
        nr = p.obj("netreceive -u -b %d" % plain_port)
        op = p.obj("oscparse")
        lt = p.obj("list trim")
        rt = p.obj("route ictus")
        rs = p.obj("route strike")
        seq = p.obj("list split 1")
        p.connect(nr, 0, op, 0)
        p.connect(op, 0, lt, 0)
        p.connect(lt, 0, rt, 0)
        p.connect(rt, 0, rs, 0)
        p.connect(rs, 0, seq, 0)
        stamped(seq, 0, "plain")
    if ctl_port or listen_later:
        d = p.obj("delay 300")
        p.connect(t, 0, d, 0)
        msgs = (["listen %d" % pd_port] if listen_later else []) + (
            ["connect localhost %d" % ctl_port] if ctl_port else []) + list(control_msgs)
        m = p.msg(" \\, ".join(msgs))
        p.connect(d, 0, m, 0)
        p.connect(m, 0, recv, 0)
    if fudi_in_port:
        # FUDI in: `probe K` is echoed at once as `probe <logical_ms> K` (the
        # test's round trip), `quit` ends pd (the test's handshake is done),
        # anything else goes into ictus-receive's inlet
        nr = p.obj("netreceive -u %d" % fudi_in_port)
        rp = p.obj("route probe quit")
        p.connect(nr, 0, rp, 0)
        stamped(rp, 0, "probe")
        bye = p.msg("\\; pd quit")
        p.connect(rp, 1, bye, 0)
        p.connect(rp, 2, recv, 0)
    if ballast:
        p.obj("array define ictus-test-ballast %d" % ballast)
    end = p.obj("delay %d" % int(seconds * 1000))
    q = p.msg("\\; pd quit")
    p.connect(t, 0, end, 0)
    p.connect(end, 0, q, 0)
    return p.text()


def start_pd(patch_text, build, sr=48000, name="rt.pd"):
    """Starts pd in real time on the patch; returns (Popen, workdir)."""
    work = make_workdir("ictus-pdosc-")
    path = os.path.join(work, name)
    with open(path, "w") as f:
        f.write(patch_text)
    cmd = [PD, "-nogui", "-nosound", "-stderr", "-r", str(sr), "-path",
           os.path.join(build, "ictus"), "-open", path]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            cwd=work, env=PD_ENV)
    return proc, work


def wait_for_ticks(listener, timeout=20.0, count=20):
    """Waits until pd reports `count` ticks (it is up and its ports are open)."""
    t0 = time.time()
    while time.time() - t0 < timeout:
        if sum(1 for _, a in listener.records() if a and a[0] == "tick") >= count:
            return True
        time.sleep(0.02)
    return False


def wait_records(listener, pred, what, timeout=20.0, required=True):
    """Handshake: the records once pred holds for them. At the deadline: a failed
    check naming `what`, or (required=False) the records as they are, for the
    test's own checks to say what is missing."""
    t0 = time.time()
    while True:
        records = listener.records()
        if pred(records):
            return records
        if time.time() - t0 >= timeout:
            if required:
                listener.require_intact()
            check(not required, "%s within %g s" % (what, timeout))
            return records
        time.sleep(0.02)


def quit_pd(proc, fudi_port, timeout=30.0):
    """Ends pd by handshake (`quit` to the patch's FUDI port, sent again every
    second until pd has exited or the deadline passed) and returns its log."""
    t_end = time.time() + timeout
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        while True:
            s.sendto(b"quit;\n", ("127.0.0.1", fudi_port))
            try:
                log, _ = proc.communicate(timeout=min(1.0, max(0.0, t_end - time.time())))
                return log
            except subprocess.TimeoutExpired:
                if time.time() >= t_end:
                    raise


def unexplained_late(late_strikes, reported_ms, tolerance_ms):
    """The (seq, error_ms) of late_strikes that no `late` report explains: a strike
    pd handled after its time fires at once and is reported late with its lateness
    (docs/pd-osc.md), so each late strike must match one report (each report used
    once) within tolerance_ms."""
    left = list(reported_ms)
    unexplained = []
    for seq, e in late_strikes:
        match = [r for r in left if abs(r - e) <= tolerance_ms]
        if match:
            left.remove(match[0])
        else:
            unexplained.append((seq, round(e, 3)))
    return unexplained


def wall_of_logical(records, sr=48000):
    """Offset (s) such that wall = offset + logical_ms / 1000: the minimum of
    arrival - B over the tick reports, B the start of the scheduler tick (64
    samples) in which the report was made. Pd starts the tick at B no earlier
    than its wall time; the clocks and messages inside it see logical times up
    to one tick later than B, ahead of the wall clock (a [metro 2] report at 2 ms
    runs 0.67 ms into a tick of 1.33 ms), so the report's own logical time would
    bound the mapping from below, not above."""
    tick_ms = 64.0 / sr * 1000.0
    return min(t - math.floor(a[1] / tick_ms + 1e-6) * tick_ms / 1000.0
               for t, a in records if a[0] == "tick")
