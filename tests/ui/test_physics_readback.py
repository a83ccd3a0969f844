"""The physics panel tells what the daemon took (docs/ui.md, "Following the daemon"): fed the
daemon's replies on its right inlet, in pd -batch, the nuance selector and the tempo box hold
what the daemon accepted (`reply /ictus/nuance staccato`, `reply /ictus/tempo 130`), a refusal
(`error /ictus/nuance ...`, `error /ictus/tempo ...`) puts back the last accepted value after a
control was moved, and the last-reply line takes replies and errors but not the strike
telemetry (`strike end ...`). Each control's value is read by banging it through its receive
name: it sends what it holds out of the panel's first outlet."""
import argparse
import os
import subprocess
import tempfile

from ictus_tools import uitest
from ictus_tools.checks import check

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
build = os.path.abspath(ap.parse_args().build)

STEPS = ["test-in reply /ictus/nuance staccato", "ictus-physics-nuance bang",
         "ictus-physics-nuance 1", "test-in error /ictus/nuance refused", "ictus-physics-nuance bang",
         "test-in reply /ictus/tempo 130", "ictus-physics-tempo bang", "ictus-physics-tempo 200",
         "test-in error /ictus/tempo refused", "ictus-physics-tempo bang",
         "test-in strike end 7 1 50 0.01 4", "test-in pong", "pd quit"]
EXPECTED = ["out: nuance staccato", "out: nuance tenuto", "out: nuance staccato",
            "out: tempo 130", "out: tempo 200", "out: tempo 130"]

with tempfile.TemporaryDirectory(prefix="ictus-ui-readback-") as work:
    patch = os.path.join(work, "readback.pd")
    with open(patch, "w") as f:
        f.write("#N canvas 0 0 400 300 12;\n"
                "#X obj 10 10 loadbang;\n"
                "#X msg 10 40 \\; %s;\n"
                "#X obj 10 100 ictus-physics;\n"
                "#X obj 200 70 r test-in;\n"
                "#X obj 10 460 print out;\n"
                "#X obj 200 460 print shown;\n"
                "#X connect 0 0 1 0;\n#X connect 3 0 2 1;\n#X connect 2 0 4 0;\n"
                "#X connect 2 1 5 0;\n" % " \\; ".join(STEPS))
    proc = subprocess.run(uitest.PD_BATCH + ["-path", os.path.join(build, "ictus"), "-open", patch],
                          capture_output=True, text=True, timeout=60, env=uitest.PD_ENV)
log = (proc.stdout + proc.stderr).splitlines()
errors = uitest.error_lines("\n".join(l for l in log if not l.startswith("shown: ")))
check(proc.returncode == 0 and not errors, "pd ran without error lines: %s" % errors)
out = [l for l in log if l.startswith("out: ")]
check(out == EXPECTED, "the controls hold what the daemon accepted, a refusal puts back the last "
      "accepted: %s (expected %s)" % (out, EXPECTED))
shown = [l for l in log if l.startswith("shown: reply")]
check(not any("strike" in l for l in shown), "the last reply never shows telemetry: %s" % shown)
check(any("pong" in l for l in shown) and any("refused" in l for l in shown),
      "replies and errors are shown: %s" % shown)
print("ok")
