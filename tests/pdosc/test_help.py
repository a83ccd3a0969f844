"""The help patches of ictus-receive, ictus-drum, ictus_timetag and ictus_error (copied into
<build>/ictus/ with the abstractions) open in pd without an error line, also
with DSP on, and have the parts of a vanilla help patch; patches/ictus-render.pd
loads (with a file that does not exist it must only complain about that file)."""
import argparse
import os
import subprocess

from ictus_tools.checks import check
from ictus_tools.pdrun import PD_BATCH, PD_ENV, error_lines

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
build = os.path.abspath(args.build)

for name, obj in (("ictus-receive-help.pd", "ictus-receive"), ("ictus-drum-help.pd", "ictus-drum"),
                  ("ictus_timetag-help.pd", "ictus_timetag"), ("ictus_error-help.pd", "ictus_error")):
    path = os.path.join(build, "ictus", name)
    check(os.path.isfile(path), "%s is in the library folder" % name)
    cmd = PD_BATCH + ["-path", build, "-open", path, "-send", "pd dsp 1", "-send", "pd quit"]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=60, env=PD_ENV)
    log = proc.stdout + proc.stderr
    bad = error_lines(log)
    check(proc.returncode == 0 and not bad and not log.strip(),
          "%s opens without errors or output%s" % (name, "" if not log.strip() else ": " + log))
    text = open(path).read()
    check("pd reference" in text and "See also" in text and "ictus 0.1.0" in text,
          "%s has [pd reference], see also and the version" % name)
    check(("#X obj 20 14 %s" % obj) in text, "%s shows %s on top" % (name, obj))
    if obj not in ("ictus_timetag", "ictus_error"):
        check("dac~" in text, "%s has a working example with dac~" % name)
