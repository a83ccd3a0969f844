"""The main patch in the Pd GUI under Xvfb: a screenshot kept in
<build>/artifacts/main-patch.png, checked to be non-blank and to show the three
panels (graph-on-parent abstractions, drawn on the main patch) side by side in
Figure 6's order: physics (left), graphics (middle), sound (right), each in its
own background colour over most of its 300/200/280 x 340 pixel area."""
import argparse
import os
import shutil
import subprocess
import time

from ictus_tools import uitest
from ictus_tools.checks import check, fail

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
build = os.path.abspath(args.build)
art = uitest.artifacts_dir(build)
if not shutil.which("wish"):
    uitest.skip_or_fail("Tk's wish is missing (Debian package puredata-gui)", missing_package=True)

# panel colours (the [cnv] of each panel) and areas in pixels
PANELS = {"physics": ((220, 230, 242), 300 * 340), "graphics": ((225, 238, 220), 200 * 340),
          "sound": ((242, 228, 216), 280 * 340)}

main = os.path.join(build, "patches", "ictus.pd")
copy = os.path.join(build, "patches", "ictus-test-gui-%d.pd" % os.getpid())
with open(copy, "w") as f:  # not listening on UDP 9000: another test may hold it
    f.write(open(main).read().replace("ictus-receive 9000", "ictus-receive 0"))
x = uitest.Xvfb(1280, 900)
pd = None
shot = os.path.join(art, "main-patch.png")
counts = {}
try:
    log_path = copy + ".log"
    pd = subprocess.Popen([uitest.PD, "-nosound", "-stderr", "-open", copy],
                          stdout=open(log_path, "w"), stderr=subprocess.STDOUT, env=x.env())
    deadline = time.time() + 60  # the GUI comes up in ~2 s alone, much later on a loaded machine
    while time.time() < deadline:
        time.sleep(1.0)
        if pd.poll() is not None:
            fail("pd exited: " + open(log_path).read())
        x.screenshot(shot)
        img = uitest.load_image(shot)
        counts = {k: ((img == c).all(axis=2)) for k, (c, _) in PANELS.items()}
        if all(m.sum() > 0.5 * area for m, (_, area) in zip(counts.values(), PANELS.values())):
            time.sleep(0.5)  # let the GUI finish drawing, then the kept shot
            x.screenshot(shot)
            img = uitest.load_image(shot)
            counts = {k: ((img == c).all(axis=2)) for k, (c, _) in PANELS.items()}
            break
    # the log up to now: shutting the X server down later makes the GUI (wish) print
    # an X I/O error on its way out, which is not the patch's
    log = open(log_path).read()
finally:
    if pd is not None and pd.poll() is None:
        pd.terminate()
        try:
            pd.wait(5)
        except subprocess.TimeoutExpired:
            pd.kill()
            pd.wait()
    x.stop()
    os.remove(copy)

print("artefact: " + shot)
os.remove(log_path)
bad = [l for l in uitest.error_lines(log) if "gem.conf" not in l and "DeckLink" not in l]
check(not bad, "pd with its GUI logs no error lines (Tcl errors included)" + ("" if not bad else ":\n" + "\n".join(bad)))
img = uitest.load_image(shot)
colours = len(set(map(tuple, img.reshape(-1, 3))))
check(colours > 20 and img.std() > 20, "the screenshot is not blank (%d colours, std %.0f)" % (colours, img.std()))
xs = {}
for k, m in counts.items():
    n = int(m.sum())
    area = PANELS[k][1]
    check(0.5 * area < n <= area, "the %s panel is drawn: %d px of its colour (area %d)" % (k, n, area))
    xs[k] = m.nonzero()[1].mean()
check(xs["physics"] < xs["graphics"] < xs["sound"],
      "panels left to right: physics (x %.0f), graphics (x %.0f), sound (x %.0f)"
      % (xs["physics"], xs["graphics"], xs["sound"]))
