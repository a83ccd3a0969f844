"""Shared pieces of the tests/ui tests: where things are, how a test skips, an Xvfb
display of its own, a screenshot, and a synthetic pose stream (docs/osc.md) built
here from a standing figure, independently of the daemon."""
import os
import queue
import shutil
import signal
import subprocess
import sys
import threading
import time

from ictus_tools import ROOT as REPO  # noqa: F401 (uitest.REPO in the tests)
from ictus_tools import oscpacket
from ictus_tools.checks import fail
from ictus_tools.pdrun import PD, PD_BATCH, PD_ENV, error_lines, free_udp_port  # noqa: F401

SKIP = 77


def stop(process, timeout_s=10):
    """Terminates a child if it still runs (SIGTERM, then SIGKILL after timeout_s) and reaps it."""
    if process is None or process.poll() is not None:
        return
    process.terminate()
    try:
        process.wait(timeout_s)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()


class PdLines:
    """What a process prints (pd, or another: name it), line by line, read by a thread
    (follow): wait_for(pred, what, timeout) is a test's handshake, the next line that pred
    accepts within a deadline (the test fails naming the process and its last lines
    otherwise); `printed` holds every line waited over."""

    def __init__(self, name="pd"):
        self.name = name
        self.queue = queue.Queue()
        self.printed = []

    def follow(self, stream):
        threading.Thread(target=self._read, args=(stream,), daemon=True).start()

    def _read(self, stream):
        for line in stream:
            self.queue.put(line.rstrip("\n"))
        self.queue.put(None)  # the process closed its output: it has ended

    def wait_for(self, pred, what, timeout=60):
        deadline = time.time() + timeout
        while time.time() < deadline:
            try:
                line = self.queue.get(timeout=0.2)
            except queue.Empty:
                continue
            if line is None:
                self.queue.put(None)  # a later wait fails at once too
                fail("%s: %s ended first (it printed, last lines: %s)"
                     % (what, self.name, self.printed[-25:]))
            self.printed.append(line)
            if pred(line):
                return line
        fail("%s within %g s (%s printed, last lines: %s)"
             % (what, timeout, self.name, self.printed[-25:]))

    def next_line(self, timeout):
        """The next line within `timeout` s, else "" (none yet); None once the process ended."""
        try:
            line = self.queue.get(timeout=timeout)
        except queue.Empty:
            return ""
        if line is None:
            self.queue.put(None)
        else:
            self.printed.append(line)
        return line

    def drain(self, timeout=30):
        """After the process was stopped: every line it printed, up to its end (or the deadline)."""
        deadline = time.time() + timeout
        while time.time() < deadline and self.next_line(0.2) is not None:
            pass


def skip_or_fail(reason, missing_package=False):
    """A piece that cannot run here skips (exit 77); under CI a package that
    scripts/deps.sh installs must be there, so its absence fails."""
    if missing_package and os.environ.get("CI") == "true":
        fail(reason + " (CI=true: scripts/deps.sh installs it)")
    print("SKIP: " + reason)
    sys.exit(SKIP)


def artifacts_dir(build):
    path = os.path.join(build, "artifacts")
    os.makedirs(path, exist_ok=True)
    return path


class Xvfb:
    """An X server of our own (-displayfd picks a free display number)."""

    def __init__(self, width=1280, height=800):
        if not shutil.which("Xvfb"):
            skip_or_fail("Xvfb not installed (Debian package xvfb)", missing_package=True)
        r, w = os.pipe()
        self.proc = subprocess.Popen(
            ["Xvfb", "-displayfd", str(w), "-screen", "0", "%dx%dx24" % (width, height),
             "-nolisten", "tcp", "+extension", "GLX"],
            pass_fds=(w,), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        os.close(w)
        number = b""
        deadline = time.time() + 10
        while time.time() < deadline and not number.endswith(b"\n"):
            chunk = os.read(r, 16)
            if not chunk:
                break
            number += chunk
        os.close(r)
        if not number.strip():
            self.stop()
            skip_or_fail("Xvfb did not start")
        self.display = ":" + number.decode().strip()

    def env(self):
        env = dict(PD_ENV)
        env["DISPLAY"] = self.display
        # Mesa's software rasteriser: no GPU here
        env["LIBGL_ALWAYS_SOFTWARE"] = "1"
        return env

    def screenshot(self, path):
        if not shutil.which("import"):
            skip_or_fail("ImageMagick's import not installed (Debian package imagemagick)",
                         missing_package=True)
        subprocess.run(["import", "-display", self.display, "-window", "root", path],
                       check=True, timeout=20, capture_output=True)
        return path

    def stop(self):
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(5)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()


def load_image(path):
    try:
        from PIL import Image
    except ImportError:
        skip_or_fail("python3-pil not installed", missing_package=True)
    import numpy as np
    return np.asarray(Image.open(path).convert("RGB")).astype(int)


# A standing figure facing +Z (its left is +X), y up, metres: the joint centres of the
# 20 bodies in docs/character.md's order, both sticks held over a drum in front.
FIGURE = [
    (0.0, 0.95, 0.0),    # 0 pelvis
    (0.0, 1.05, 0.0),    # 1 abdomen
    (0.0, 1.25, 0.0),    # 2 thorax
    (0.0, 1.45, 0.0),    # 3 neck
    (0.0, 1.52, 0.0),    # 4 upper neck
    (0.0, 1.58, 0.0),    # 5 head
    (0.03, 1.42, 0.0),   # 6 left clavicle
    (0.19, 1.42, 0.0),   # 7 left upper arm (shoulder)
    (0.25, 1.15, 0.06),  # 8 left forearm (elbow)
    (0.22, 1.0, 0.3),    # 9 left hand (wrist)
    (-0.03, 1.42, 0.0),  # 10 right clavicle
    (-0.19, 1.42, 0.0),  # 11
    (-0.25, 1.15, 0.06),  # 12
    (-0.22, 1.0, 0.3),   # 13
    (0.1, 0.9, 0.0),     # 14 left thigh (hip)
    (0.11, 0.5, 0.02),   # 15 left shank (knee)
    (0.11, 0.09, 0.0),   # 16 left foot (ankle)
    (-0.1, 0.9, 0.0),    # 17
    (-0.11, 0.5, 0.02),  # 18
    (-0.11, 0.09, 0.0),  # 19
]
STICKS = [((0.06, 0.82, 0.62), (0.22, 0.98, 0.33)),   # left: tip, butt
          ((-0.06, 0.82, 0.62), (-0.22, 0.98, 0.33))]
DRUM = ((0.0, 0.76, 0.6), 0.178)
IDENTITY = (1.0, 0.0, 0.0, 0.0)


def pose_bundle(time_s, head_quat=IDENTITY):
    """One pose frame as ictusd sends it: a bundle, timetag 'immediately'."""
    msgs = [oscpacket.message("/ictus/pose/frame", "f", time_s)]
    for i, p in enumerate(FIGURE):
        q = head_quat if i == 5 else IDENTITY
        msgs.append(oscpacket.message("/ictus/pose/body", "ifffffff", i, *p, *q))
    for hand, (tip, butt) in enumerate(STICKS):
        msgs.append(oscpacket.message("/ictus/pose/stick", "iffffff", hand, *tip, *butt))
    msgs.append(oscpacket.message("/ictus/pose/drum", "iffff", 0, *DRUM[0], DRUM[1]))
    return oscpacket.bundle(b"\0\0\0\0\0\0\0\1", *msgs)


def top_level_boxes(records):
    """Each box of a patch's top level (its records, split at the unescaped ';\n'), in Pd's
    numbering, the one '#X connect' uses: (index, kind, words); a subpatch counts as one box
    (kind 'restore')."""
    depth, n, boxes = 0, 0, []
    for r in records:
        if r.startswith("#N canvas"):
            depth += 1
        elif r.startswith("#X restore"):
            depth -= 1
            if depth == 1:
                boxes.append((n, "restore", r.split()))
                n += 1
        elif depth == 1 and r.split()[1] in ("obj", "msg", "text", "floatatom", "symbolatom",
                                             "listbox"):
            words = r.split()
            boxes.append((n, words[1], words))
            n += 1
    return boxes


def top_level_index(records):
    """The number of top-level boxes, and the index of each object class's first box."""
    boxes = top_level_boxes(records)
    index = {}
    for n, kind, words in boxes:
        if kind == "obj" and len(words) > 4:
            index.setdefault(words[4], n)
    return len(boxes), index


def main_patch_on_ports(build, pd_port, daemon_port):
    """The main patch as built (its text and its records), listening on pd_port and sending
    to daemon_port instead of 9000 / 9001, checked to have those two first."""
    from ictus_tools.checks import check
    main = open(os.path.join(build, "patches", "ictus.pd")).read()
    check("ictus-receive 9000;" in main and "connect 127.0.0.1 9001;" in main,
          "the main patch listens on 9000 and sends to 9001")
    main = main.replace("ictus-receive 9000;", "ictus-receive %d;" % pd_port)
    main = main.replace("connect 127.0.0.1 9001;", "connect 127.0.0.1 %d;" % daemon_port)
    return main, [r for r in main.split(";\n") if r.strip()]
