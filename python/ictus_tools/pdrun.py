"""Helpers for the tests that run the real pd binary in batch mode.

A test builds a patch from a list of boxes and connections, runs
`pd -nogui -nosound -batch -nrt -stderr`, and reads back what the patch wrote into a
table (32-bit float WAV via soundfiler, see docs/externals.md).

Every batch pd of the tests and benchmarks runs with -nrt. As root (CI), pd takes
SCHED_FIFO priority 6 unless told not to; a batch render never sleeps, so two of them
held both cores at that priority, and a real-time test's pd, at the same priority, got no
CPU for seconds (its reports stopped for 4 s, the round trip to it was 1.8 s)."""
import atexit
import fcntl
import os
import random
import re
import shutil
import socket
import subprocess
import tempfile

import numpy as np

from ictus_tools import checks

PD = os.environ.get("ICTUS_PD", "pd")
# pd rendering offline, as fast as the CPU allows: no GUI, no audio device, its messages on
# stderr, and -nrt: run as root pd would otherwise take SCHED_FIFO even in batch mode, and
# a render that never sleeps would starve every real-time pd beside it.
PD_BATCH = [PD, "-nogui", "-nosound", "-batch", "-nrt", "-stderr"]
# Under the ASan build, the sanitizer runtime to preload into pd (which is not
# instrumented itself); python is left alone.
PD_ENV = dict(os.environ)
if os.environ.get("ICTUS_PD_PRELOAD"):
    PD_ENV["LD_PRELOAD"] = os.environ["ICTUS_PD_PRELOAD"]
# What Pd prints when something went wrong while loading or running a patch.
ERROR_RE = re.compile(r"error|couldn't|bad arguments|no method|not found|warning", re.I)


class Patch:
    """A flat Pd patch: add boxes (returns their index), connect them."""

    def __init__(self, declare=None):
        self.lines = ["#N canvas 0 0 800 600 12;"]
        if declare:
            self.lines.append("#X declare %s;" % declare)
        self.count = 0

    def obj(self, text):
        self.lines.append("#X obj %d %d %s;" % (10 + 30 * self.count, 10 + 20 * self.count, text))
        self.count += 1
        return self.count - 1

    def msg(self, text):
        self.lines.append("#X msg %d %d %s;" % (10 + 30 * self.count, 10 + 20 * self.count, text))
        self.count += 1
        return self.count - 1

    def table(self, name, size):
        return self.obj("table %s %d" % (name, size))

    def subpatch(self, name, sub):
        """Inserts `sub` (a Patch) as [pd name]; returns its index."""
        self.lines.append("#N canvas 0 0 600 400 %s 0;" % name)
        self.lines.extend(sub.lines[1:])
        self.lines.append("#X restore %d %d pd %s;" % (10 + 30 * self.count, 10 + 20 * self.count, name))
        self.count += 1
        return self.count - 1

    def connect(self, a, outlet, b, inlet):
        self.lines.append("#X connect %d %d %d %d;" % (a, outlet, b, inlet))

    def text(self):
        return "\n".join(self.lines) + "\n"


# Ports the tests listen on are drawn from below the kernel's ephemeral range
# (net.ipv4.ip_local_port_range), where the kernel never hands one to another
# process's unbound socket, and each is reserved by a lock file held until this
# process exits, so that tests running side by side never draw the same one.
# $TMPDIR, else /tmp: the same rule as the C++ twin (not tempfile's, which also reads TEMP
# and TMP), so that both find the same reservations.
PORT_LOCK_DIR = os.path.join(os.environ.get("TMPDIR") or "/tmp", "ictus-test-ports")
_held_port_locks = []


def _port_candidates():
    try:
        with open("/proc/sys/net/ipv4/ip_local_port_range") as f:
            low, high = (int(v) for v in f.read().split())
    except (OSError, ValueError):
        low, high = 32768, 60999
    if low - 20000 >= 2000:
        return range(20000, low)
    if 65535 - high >= 2000:
        return range(high + 1, 65536)
    return range(max(1024, low), high + 1)


def _bindable(port, kind):
    with socket.socket(socket.AF_INET, kind) as s:
        try:
            s.bind(("127.0.0.1", port))
        except OSError:
            return False
    return True


def _open_lock(path):
    """The lock file's descriptor, or None when this user cannot open it (another user's
    lock file, read-only to us: flock works on a read-only descriptor, so that is tried
    next; else the port is skipped)."""
    try:
        fd = os.open(path, os.O_CREAT | os.O_RDWR, 0o666)
    except PermissionError:
        try:
            return os.open(path, os.O_RDONLY)
        except OSError:
            return None
    try:
        os.fchmod(fd, 0o666)  # every user's tests may lock it (the umask took bits off)
    except OSError:
        pass  # another user's file: it stays as it is
    return fd


def free_port(kind=socket.SOCK_DGRAM):
    """A port on 127.0.0.1 that is free (UDP, or TCP with kind=socket.SOCK_STREAM),
    outside the ephemeral range and reserved for this process (see above)."""
    if not os.path.isdir(PORT_LOCK_DIR):
        os.makedirs(PORT_LOCK_DIR, exist_ok=True)
        try:
            os.chmod(PORT_LOCK_DIR, 0o1777)  # shared by every user's tests, as /tmp is
        except OSError:
            pass
    candidates = _port_candidates()
    rng = random.SystemRandom()
    for _ in range(2000):
        port = rng.choice(candidates)
        fd = _open_lock(os.path.join(PORT_LOCK_DIR, "%d.lock" % port))
        if fd is None:
            continue
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            os.close(fd)
            continue
        if _bindable(port, kind):
            _held_port_locks.append(fd)
            return port
        os.close(fd)
    raise RuntimeError("no free port in %d..%d after 2000 tries (lock files in %s)"
                       % (candidates[0], candidates[-1], PORT_LOCK_DIR))


def free_udp_port():
    """A UDP port on 127.0.0.1 that is free and reserved for this process."""
    return free_port(socket.SOCK_DGRAM)


def recorder(p, tables, seconds, sr, wav_path, quit_extra=None):
    """Adds: loadbang -> dsp on, start every [tabwrite~ t] for `tables` (a list
    of (source_index, outlet, table_name)), and after `seconds` write them all
    into one multichannel WAV and quit. Recording starts with the first DSP block,
    at logical time 0, so sample i of the WAV is logical time i / sr."""
    n = int(round(seconds * sr))
    lb = p.obj("loadbang")
    trig = p.obj("t b b b")
    p.connect(lb, 0, trig, 0)
    dsp = p.msg("\\; pd dsp 1")
    p.connect(trig, 2, dsp, 0)
    names = []
    for src, outlet, name in tables:
        p.table(name, n)
        tw = p.obj("tabwrite~ %s" % name)
        p.connect(src, outlet, tw, 0)
        p.connect(trig, 1, tw, 0)
        names.append(name)
    done = p.obj("delay %.17g" % (seconds * 1000.0 + 10.0))
    p.connect(trig, 0, done, 0)
    write = p.msg("write -wave -bytes 4 %s %s" % (wav_path, " ".join(names)))
    sf = p.obj("soundfiler")
    quit_msg = p.msg("\\; pd quit")
    t2 = p.obj("t b b")
    p.connect(done, 0, t2, 0)
    p.connect(t2, 1, write, 0)
    p.connect(write, 0, sf, 0)
    p.connect(t2, 0, quit_msg, 0)
    return trig


def send_each_ms(p, target, messages, tail_ms=20):
    """Adds: at load, each of `messages` (a message box's text) into target's left
    inlet, one logical millisecond apart from 1 ms on; pd quits tail_ms after the
    last (in batch pd the delays take no wall time)."""
    lb = p.obj("loadbang")
    for k, text in enumerate(messages):
        d = p.obj("delay %d" % (1 + k))
        m = p.msg(text)
        p.connect(lb, 0, d, 0)
        p.connect(d, 0, m, 0)
        p.connect(m, 0, target, 0)
    q = p.obj("delay %d" % (len(messages) + tail_ms))
    qm = p.msg("\\; pd quit")
    p.connect(lb, 0, q, 0)
    p.connect(q, 0, qm, 0)


def check_bad_messages(errors, name, bad):
    """Of a run that sent the messages `bad` to [name] (send_each_ms): every error
    line names `name` ("error: NAME: ..."), and each bad message `WORD REST` has one
    starting "error: NAME: WORD " and ending "got: REST" ("got: bang" for a bare
    WORD). Checks made with ictus_tools.checks.check; returns whether all held."""
    check = checks.check
    prefix = "error: %s: " % name
    ok = check(all(e.startswith(prefix) for e in errors), "every error line names %s: others %s"
               % (name, [e for e in errors if not e.startswith(prefix)][:4]))
    for text in bad:
        word, _, rest = text.partition(" ")
        said = [e for e in errors if e.startswith(prefix + word + " ")
                and e.rstrip().endswith("got: " + (rest or "bang"))]
        ok = check(said, "'%s': an error line of %s naming %s and quoting it (%s)"
                   % (text, name, word, said[:1])) and ok
    return ok


def run_pd(patch_text, libdir, sr=48000, extra_args=(), workdir=None, name="test.pd",
           timeout=120):
    """Writes the patch into workdir and runs pd on it; returns (returncode, stderr)."""
    workdir = workdir or make_workdir("ictus-pd-")
    path = os.path.join(workdir, name)
    with open(path, "w") as f:
        f.write(patch_text)
    cmd = PD_BATCH + ["-r", str(sr), "-path", libdir]
    cmd += list(extra_args) + ["-open", path]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, cwd=workdir,
                          env=PD_ENV)
    return proc.returncode, proc.stdout + proc.stderr


def run_recorded(p, libdir, sr, prefix):
    """Runs Patch p, whose recorder() was given the path "WAV", with that path in a new
    workdir: (returncode, log, samples [n, ch] or None when pd wrote no WAV)."""
    work = make_workdir(prefix)
    wav = os.path.join(work, "out.wav")
    rc, log = run_pd(p.text().replace("WAV", wav), libdir, sr=sr, workdir=work)
    return rc, log, read_wav_float(wav)[0] if os.path.exists(wav) else None


def read_wav_float(path):
    """Reads a 32-bit float WAV (what soundfiler writes) -> (samples [n, ch], sr)."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] != b"RIFF" or data[8:12] != b"WAVE":
        raise ValueError("%s: not a WAV file" % path)
    pos, fmt, frames = 12, None, None
    while pos + 8 <= len(data):
        cid, size = data[pos:pos + 4], int.from_bytes(data[pos + 4:pos + 8], "little")
        body = data[pos + 8:pos + 8 + size]
        if cid == b"fmt ":
            tag = int.from_bytes(body[0:2], "little")
            channels = int.from_bytes(body[2:4], "little")
            sr = int.from_bytes(body[4:8], "little")
            bits = int.from_bytes(body[14:16], "little")
            if tag == 0xFFFE:
                tag = int.from_bytes(body[24:26], "little")
            fmt = (tag, channels, sr, bits)
        elif cid == b"data":
            frames = body
        pos += 8 + size + (size & 1)
    if fmt is None or frames is None:
        raise ValueError("%s: no fmt or data chunk" % path)
    tag, channels, sr, bits = fmt
    if tag != 3 or bits != 32:
        raise ValueError("%s: expected 32-bit float, got tag %d, %d bits" % (path, tag, bits))
    samples = np.frombuffer(frames, dtype="<f4").reshape(-1, channels)
    return samples, sr


def read_wav_any(path):
    """A WAV of 32-bit float or 16-/24-bit integer PCM -> (samples [n, ch] as
    float64, full scale 1.0, sr, bits, is_float)."""
    import wave
    try:
        x, sr = read_wav_float(path)
        return x.astype(np.float64), sr, 32, True
    except ValueError as e:
        if "expected 32-bit float" not in str(e):
            raise
    with wave.open(path, "rb") as w:
        ch, width, sr, n = w.getnchannels(), w.getsampwidth(), w.getframerate(), w.getnframes()
        raw = w.readframes(n)
    if width == 2:
        v = np.frombuffer(raw, dtype="<i2").astype(np.float64) / 32768.0
    elif width == 3:
        b = np.frombuffer(raw, dtype=np.uint8).reshape(-1, 3).astype(np.int32)
        i = b[:, 0] | (b[:, 1] << 8) | (b[:, 2] << 16)
        i = np.where(i >= 1 << 23, i - (1 << 24), i)
        v = i.astype(np.float64) / float(1 << 23)
    else:
        raise ValueError("%s: %d-byte integer samples not read here" % (path, width))
    return v.reshape(-1, ch), sr, 8 * width, False


_workdirs = []


def _cleanup():
    if checks.failed() or os.environ.get("ICTUS_KEEP_TMP"):
        for d in _workdirs:
            print("kept for inspection:", d)
        return
    for d in _workdirs:
        shutil.rmtree(d, ignore_errors=True)


atexit.register(_cleanup)


def make_workdir(prefix):
    """A temporary folder for patches and WAVs, removed at exit unless a check
    failed (or ICTUS_KEEP_TMP is set)."""
    d = tempfile.mkdtemp(prefix=prefix)
    _workdirs.append(d)
    return d


def error_lines(log):
    return [l for l in log.splitlines() if ERROR_RE.search(l)]


# Gem's start-up chatter (no config file, an optional capture plugin's missing
# library) is not an error of the patch.
GEM_NOISE = ("gem.conf", "libDeckLinkAPI")


def open_patch(path, extra_args=(), timeout=60):
    """Opens a patch in pd batch mode, switches DSP on and quits: (exit status, the error
    lines of pd's output but Gem's start-up chatter)."""
    cmd = list(PD_BATCH) + list(extra_args) + [
        "-open", path, "-send", "pd dsp 1", "-send", "pd quit"]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, env=PD_ENV)
    log = proc.stdout + proc.stderr
    return proc.returncode, [l for l in error_lines(log) if not any(n in l for n in GEM_NOISE)]


def membrane_modes_from_log(log, prefix=""):
    """{name: [(label, f, t60)]}: the modes (cos partners only) that each `membrane~ PREFIXname`
    posts on `print`, from pd's log."""
    out, cur = {}, None
    for line in log.splitlines():
        m = re.match(r"membrane~ (\S+): radius", line)
        if m:
            name = m.group(1)
            cur = out.setdefault(name[len(prefix):], []) if name.startswith(prefix) else None
            continue
        m = re.match(r"\s*mode\s+\d+ \((\d+),(\d+)\)\s*(sin|cos)?: +([\d.]+) Hz  T60 ([\d.]+) s", line)
        if m and cur is not None and m.group(3) != "sin":
            cur.append(("(%s,%s)" % (m.group(1), m.group(2)), float(m.group(4)), float(m.group(5))))
    return out
