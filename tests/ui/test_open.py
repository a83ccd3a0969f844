"""The main patch (<build>/patches/ictus.pd) and EVERY help patch of help/ (globbed
now, so a new one is covered without editing this test) open in the real pd
(-nogui -batch -stderr, DSP on) without an error line; each help patch is in the
library folder <build>/ictus/, where Pd looks for it, and the help patches of
this area (ui) have the parts of a vanilla help patch."""
import argparse
import glob
import os

from ictus_tools import pdrun, uitest
from ictus_tools.checks import check

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
build = os.path.abspath(args.build)
libdir = os.path.join(build, "ictus")


def open_patch(path, name):
    status, bad = pdrun.open_patch(path)
    check(status == 0 and not bad,
          "%s opens without error lines%s" % (name, "" if not bad else ":\n" + "\n".join(bad)))


main = os.path.join(build, "patches", "ictus.pd")
check(os.path.isfile(main), "the main patch is in the build: %s" % main)
# A copy beside it on a free port: the test must not depend on UDP 9000 being free.
text = open(main).read()
check("ictus-receive 9000" in text, "the main patch listens on UDP 9000 (ictusd's default --target)")
copy = os.path.join(build, "patches", "ictus-test-open-%d.pd" % os.getpid())
with open(copy, "w") as f:
    f.write(text.replace("ictus-receive 9000", "ictus-receive 0"))
try:
    open_patch(copy, "patches/ictus.pd")
finally:
    os.remove(copy)
for name in ("ictus-physics", "ictus-graphics", "ictus-sound-panel", "ictus-view", "ictus-sound"):
    check(("#X obj" in text) and (" %s" % name) in text, "the main patch uses [%s]" % name)

helps = sorted(glob.glob(os.path.join(uitest.REPO, "help", "*.pd")))
check(len(helps) >= 10, "help/ has the help patches (%d files)" % len(helps))
for src in helps:
    name = os.path.basename(src)
    path = os.path.join(libdir, name)
    check(os.path.isfile(path), "%s is copied into the library folder" % name)
    open_patch(path, name)

for obj in ("ictus-physics", "ictus-graphics", "ictus-sound-panel", "ictus-view"):
    help_text = open(os.path.join(libdir, obj + "-help.pd")).read()
    check("#X obj 20 14 %s;" % obj in help_text and "pd reference" in help_text
          and "See also" in help_text and "ictus 0.1.0" in help_text,
          "%s-help.pd: the object on top, [pd reference], see also, the version" % obj)

meta = open(os.path.join(libdir, "ictus-meta.pd")).read()
objects = [l for l in meta.splitlines() if "OBJECTS" in l]
check(len(objects) == 1, "ictus-meta.pd has an OBJECTS line")
for obj in ("membrane~", "contact~", "ictus_timetag", "ictus-receive", "ictus-drum", "ictus-sound",
            "ictus-sound-clips", "ictus-sound-synth", "ictus-sound-modal", "ictus-physics",
            "ictus-graphics", "ictus-sound-panel", "ictus-view"):
    check((" %s " % obj) in objects[0].replace(";", " "), "ictus-meta.pd lists %s" % obj)
    check(os.path.isfile(os.path.join(libdir, obj + "-help.pd")), "%s has a help patch" % obj)
# every abstraction, external and patch in the library folder is in the meta file
# (top-level patches such as ictus-render.pd are listed on the PATCHES line, with .pd)
listed = " ".join(l for l in meta.splitlines()
                  if "OBJECTS" in l or "INTERNAL" in l or "PATCHES" in l).replace(";", " ")
listed = listed.replace(".pd ", " ") + " "
for f in sorted(os.listdir(libdir)):
    stem, ext = os.path.splitext(f)
    if ext not in (".pd", ".pd_linux") or stem.endswith("-help") or stem in ("ictus-meta", "ictus"):
        continue
    if ext == ".pd_linux":
        stem = stem.replace("_tilde", "~")
    check((" %s " % stem) in listed, "ictus-meta.pd lists %s (in the library folder)" % stem)
