"""The help patches of the four sound abstractions (copied into <build>/ictus/)
open in pd -nogui -stderr with DSP on and print no error line (the switcher's
help prints only its model report, `model modal 2`), and have the parts of a
vanilla help patch: the object on top, a working example with dac~, a
[pd reference] subpatch, see also, the version."""
import argparse
import os
import subprocess

from ictus_tools.checks import check
from ictus_tools.soundrun import PD_BATCH, PD_ENV, error_lines, make_workdir

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
build = os.path.abspath(args.build)

expected_output = {"ictus-sound": ["ictus-sound: model modal 2"]}
for obj in ("ictus-sound", "ictus-sound-clips", "ictus-sound-synth", "ictus-sound-modal"):
    name = obj + "-help.pd"
    path = os.path.join(build, "ictus", name)
    check(os.path.isfile(path), "%s is in the library folder" % name)
    cmd = PD_BATCH + ["-path", build, "-open", path, "-send", "pd dsp 1", "-send", "pd quit"]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=60, env=PD_ENV)
    log = proc.stdout + proc.stderr
    lines = [l for l in log.splitlines() if l.strip()]
    check(proc.returncode == 0 and not error_lines(log) and lines == expected_output.get(obj, []),
          "%s opens without errors (output: %s)" % (name, lines))
    text = open(path).read()
    check("pd reference" in text and "See also" in text and "ictus 0.1.0" in text,
          "%s has [pd reference], see also and the version" % name)
    check(("#X obj 20 14 %s;" % obj) in text and "dac~" in text,
          "%s shows %s on top and a working example with dac~" % (name, obj))

# The switcher's argument picks the first model (none: modal), names or numbers.

work = make_workdir("ictus-sound-arg-")
for arg, report in (("", "model modal 2"), ("clips", "model clips 0"), ("synth", "model synth 1"),
                    ("1", "model synth 1"), ("0", "model clips 0"), ("modal", "model modal 2")):
    patch = os.path.join(work, "arg.pd")
    with open(patch, "w") as f:
        f.write("#N canvas 0 0 400 300 12;\n#X obj 10 10 ictus-sound %s;\n#X obj 10 60 print got;\n"
                "#X connect 0 2 1 0;\n" % arg)
    proc = subprocess.run(PD_BATCH + ["-path", os.path.join(build, "ictus"), "-open", patch,
                                      "-send", "pd quit"],
                          capture_output=True, text=True, timeout=60, env=PD_ENV)
    log = (proc.stdout + proc.stderr).strip()
    check(log == "got: " + report, "[ictus-sound %s] starts with %s (%s)" % (arg, report, log))
