"""The help patches open in pd with no error line, also once DSP is switched on
(contact~ looks for its membrane~ then): the copies in <build>/ictus/ with no
search path, and the sources in help/ with -path <build> (their
[declare -path . -lib ictus -lib ictus/ictus] covers both). Each has the parts a
vanilla help patch has."""
import argparse
import os
import subprocess

from ictus_tools import ROOT
from ictus_tools.checks import check
from ictus_tools.pdrun import PD_BATCH, PD_ENV, error_lines

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
build = os.path.abspath(args.build)

for name in ("membrane~-help.pd", "contact~-help.pd", "ictus-meta.pd"):
    path = os.path.join(build, "ictus", name)
    check(os.path.isfile(path), "%s is in the library folder" % name)
    source = os.path.join(ROOT, "help", name)
    # the copy beside the binaries with no search path (as Pd's help browser
    # opens it), and the source file with -path <build>
    for where, extra in ((path, []), (source, ["-path", build])):
        cmd = list(PD_BATCH) + extra + [
            "-open", where, "-send", "pd dsp 1", "-send", "pd quit"]
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=60, env=PD_ENV)
        log = proc.stdout + proc.stderr
        bad = error_lines(log)
        check(proc.returncode == 0 and not bad, "%s opens without errors (%s)%s"
              % (where, " ".join(extra) or "no -path", "" if not bad else ": " + " | ".join(bad)))
    text = open(path).read()
    if name.endswith("-help.pd"):
        obj = name[:-len("-help.pd")]
        check("pd reference" in text and "See also" in text and "0.1.0" in text
              and "dac~" in text, "%s has an example with dac~, [pd reference], see also, version"
              % name)
        check("#X obj" in text and (" %s" % obj) in text, "%s shows %s" % (name, obj))
