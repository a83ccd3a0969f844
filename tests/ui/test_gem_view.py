"""[ictus-view] in Gem under Xvfb (Mesa's software GL): a synthetic pose stream sent
as OSC bundles over UDP to [ictus-receive] -> [ictus-view], two screenshots kept in
<build>/artifacts/. Checked against the figure's geometry (ictus_tools.uitest):
 - the picture is not blank: the character's colours are there, on a background;
 - the front camera looks at the character's face, so its left side (blue, world +X)
   is right of its right side (red) on the screen;
 - the head is drawn from its body's quaternion: identity -> the head stands up
   (taller than wide); turned 90 deg about +Z -> it lies along world -X (wider than
   tall, and its centre moves to the screen's left);
 - the rate meter reports the pose frames per second that were sent (30)."""
import argparse
import math
import os
import re
import shutil
import socket
import subprocess
import tempfile
import time

from ictus_tools import uitest
from ictus_tools.checks import check, fail

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
build = os.path.abspath(args.build)
libdir = os.path.join(build, "ictus")
art = uitest.artifacts_dir(build)

if not os.path.isdir("/usr/lib/pd/extra/Gem") and not shutil.which("pd-gem"):
    uitest.skip_or_fail("Gem is not installed (Debian package gem)", missing_package=True)

W, H = 480, 360
RATE_HZ = 30.0


port = uitest.free_udp_port()
work = tempfile.mkdtemp(prefix="ictus-ui-gem-")
patch = os.path.join(work, "view.pd")
with open(patch, "w") as f:
    f.write("#N canvas 0 0 400 300 12;\n"
            "#X obj 10 10 ictus-receive %d;\n"
            "#X obj 10 60 ictus-view;\n"
            "#X obj 10 90 print view;\n"
            "#X obj 200 10 loadbang;\n"
            "#X msg 200 40 dimen %d %d \\, camera front \\, window 1;\n"
            "#X connect 0 1 1 0;\n#X connect 1 0 2 0;\n#X connect 3 0 4 0;\n#X connect 4 0 1 0;\n"
            % (port, W, H))

x = uitest.Xvfb(800, 600)
pd = None
try:
    log_path = os.path.join(work, "pd.log")
    log = open(log_path, "w")
    pd = subprocess.Popen([uitest.PD, "-nogui", "-nosound", "-stderr", "-path", libdir, "-open", patch],
                          stdout=log, stderr=subprocess.STDOUT, env=x.env())
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)

    def stream(seconds, head_quat):
        t0 = time.time()
        n = 0
        while time.time() - t0 < seconds:
            sock.sendto(uitest.pose_bundle(n / RATE_HZ, head_quat), ("127.0.0.1", port))
            n += 1
            time.sleep(max(0.0, t0 + n / RATE_HZ - time.time()))
            if pd.poll() is not None:
                break

    stream(3.0, uitest.IDENTITY)
    text = open(log_path).read()
    if pd.poll() is not None:
        fail("pd exited early:\n" + text)
    if re.search(r"gemglxwindow|GLX|could not open display|couldn't create", text, re.I) and \
            "Direct Rendering" not in text:
        uitest.skip_or_fail("Gem could not open a GL window under Xvfb here:\n" + text[-2000:])
    shot_a = x.screenshot(os.path.join(art, "gem-view-front.png"))
    half = math.sqrt(0.5)
    stream(1.5, (half, 0.0, 0.0, half))  # head turned 90 deg about +Z
    shot_b = x.screenshot(os.path.join(art, "gem-view-head-turned.png"))
finally:
    uitest.stop(pd, 5)
    x.stop()

text = open(log_path).read()
print("artefacts: %s, %s" % (shot_a, shot_b))
bad = [l for l in uitest.error_lines(text)
       if "gem.conf" not in l and "DeckLink" not in l]
check(not bad, "pd log has no error lines" + ("" if not bad else ":\n" + "\n".join(bad)))


def classes(img):
    r, g, b = img[..., 0], img[..., 1], img[..., 2]
    return {
        "blue": (b > r + 50) & (b > g + 20),          # the character's left side
        "red": (r > g + 60) & (r > b + 60),            # its right side
        "yellow": (r > 120) & (g > 90) & (b < 0.6 * g) & (r > b + 60),  # the head
        "background": (abs(r - 31) <= 2) & (abs(g - 31) <= 2) & (abs(b - 38) <= 2),
    }


def centroid(mask):
    ys, xs = mask.nonzero()
    return xs.mean(), ys.mean(), xs.max() - xs.min() + 1, ys.max() - ys.min() + 1


def gem_window(img):
    """The Gem window's pixels: the root window is black around it (no window
    manager places it, Gem puts it at its own offset)."""
    lit = img.sum(axis=2) > 0
    ys, xs = lit.nonzero()
    y0, x0 = ys.min(), xs.min()
    return img[y0:y0 + H, x0:x0 + W]


a = gem_window(uitest.load_image(shot_a))
b = gem_window(uitest.load_image(shot_b))
check(a.shape[:2] == (H, W), "the Gem window is %dx%d" % (W, H))
ca, cb = classes(a), classes(b)
n_px = W * H
print("front: " + ", ".join("%s %d px" % (k, v.sum()) for k, v in ca.items()))
check(len(set(map(tuple, a.reshape(-1, 3)))) > 50, "the Gem view is not blank (many colours)")
check(0.3 * n_px < ca["background"].sum() < 0.97 * n_px, "the background fills most but not all of it")
for k in ("blue", "red", "yellow"):
    check(ca[k].sum() > 100, "the character's %s pixels are drawn" % k)
bx = centroid(ca["blue"])[0]
rx = centroid(ca["red"])[0]
check(bx > W / 2 + 10 and rx < W / 2 - 10,
      "front view: the left side (blue, x %.0f) is right of the right side (red, x %.0f)" % (bx, rx))
hx_a, hy_a, hw_a, hh_a = centroid(ca["yellow"])
hx_b, hy_b, hw_b, hh_b = centroid(cb["yellow"])
print("head: identity at x %.0f (%dx%d px), turned at x %.0f (%dx%d px)" % (hx_a, hw_a, hh_a, hx_b, hw_b, hh_b))
check(hh_a > 1.2 * hw_a, "identity quaternion: the head stands up (taller than wide)")
check(hw_b > 1.2 * hh_b, "head turned 90 deg about +Z: it lies sideways (wider than tall)")
check(hx_b < hx_a - 8, "head turned toward world -X: its centre moves to the screen's left")
rates = [float(v) for v in re.findall(r"view: poserate (\S+)", text)]
print("rate meter: %s" % rates)
check(any(abs(r - RATE_HZ) <= 2 for r in rates[1:]), "the rate meter reports ~%g pose frames/s" % RATE_HZ)
shutil.rmtree(work, ignore_errors=True)
