"""[ictus-sound-panel]'s messages, in the real pd (batch): a preset into its inlet
sets each control and sends it as if moved by hand. Checked against numbers
computed here: the daemon gets drum/density = mass / (pi a^2) with the radius in
force (membrane~'s own rule, docs/externals.md), drum/radius and drum/tension
mirror the sound's; values outside a control's range are clamped to it, with a line naming it; the
model report of [ictus-sound] (model <name> <index>) is shown, not sent back
(that would loop); an out-of-range value and an unknown message are named in a line."""
import argparse
import math
import os
import subprocess
import tempfile

from ictus_tools import uitest
from ictus_tools.checks import check

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
build = os.path.abspath(args.build)

PRESET = [("mass", 0.0261), ("radius", 0.2), ("mass", 0.05), ("tension", 4500), ("modes", 5000),
          ("t60", 0.001), ("hfdamp", 3), ("volume", 0.5), ("model", "synth 1"), ("bogus", 1)]
with tempfile.TemporaryDirectory(prefix="ictus-ui-sound-") as work:
    patch = os.path.join(work, "sp.pd")
    with open(patch, "w") as f:
        f.write("#N canvas 0 0 400 300 12;\n#X obj 10 10 loadbang;\n#X msg 10 40 %s;\n"
                "#X obj 10 70 ictus-sound-panel;\n#X obj 10 100 print snd;\n#X obj 200 100 print dmn;\n"
                "#X connect 0 0 1 0;\n#X connect 1 0 2 0;\n#X connect 2 0 3 0;\n#X connect 2 1 4 0;\n"
                % " \\, ".join("%s %s" % kv for kv in PRESET))
    proc = subprocess.run(uitest.PD_BATCH + ["-path", os.path.join(build, "ictus"), "-open", patch,
                                             "-send", "pd quit"],
                          capture_output=True, text=True, timeout=60, env=uitest.PD_ENV)
lines = [l.strip() for l in (proc.stdout + proc.stderr).splitlines() if l.strip()]
print("\n".join(lines))
snd = [l[5:].split() for l in lines if l.startswith("snd: ")]
dmn = [l[5:].split() for l in lines if l.startswith("dmn: ")]
sound = [(w[0], float(w[1])) for w in snd]
check(sound == [("mass", 0.0261), ("radius", 0.2), ("mass", 0.05), ("tension", 4500), ("modes", 4096),
                ("t60", 0.005), ("hfdamp", 3), ("volume", 0.5)],
      "to ictus-sound: each value in order, modes and t60 clamped to 4096 and 0.005")
daemon = [(w[0], float(w[1])) for w in dmn]
names = [d[0] for d in daemon]
check(names == ["drum/density", "drum/radius", "drum/density", "drum/tension"],
      "to ictusd: density, radius, density, tension (%s)" % names)
# defaults: a = 0.178 m (membrane~'s) until the preset's radius 0.2
for got, (mass, a) in zip([d[1] for d in daemon if d[0] == "drum/density"], ((0.0261, 0.178), (0.05, 0.2))):
    want = mass / (math.pi * a * a)
    check(abs(got - want) <= 1e-5 * want, "drum/density %.6g = %g kg / (pi %g^2 m^2) = %.6g" % (got, mass, a, want))
check(("drum/radius", 0.2) in daemon and ("drum/tension", 4500) in daemon, "radius and tension mirrored to ictusd")
check(not any(l.startswith("snd: model") for l in lines), "the model report is not sent back to ictus-sound")
# error lines (Pd's Find Last Error finds them), each naming the panel and the control
errs = [l.strip() for l in uitest.error_lines("\n".join(lines))]
check(any(l.endswith("ictus-sound-panel: unknown message: bogus 1") for l in errs),
      "an unknown message is named in an error line")
for want in ("ictus-sound-panel: modes: expected 1 to 4096 but got 5000 (clamped)",
             "ictus-sound-panel: t60: expected 0.005 to 60 but got 0.001 (clamped)"):
    check(any(l.endswith(want) for l in errs), "out of range, an error line: %r" % want)
check(len(errs) == 3, "exactly those three error lines (%d): %s" % (len(errs), errs))

# The panel's messages against the real [ictus-sound] (docs/sound.md's interface):
# every one is accepted without an error line, DSP on, and a model switch is
# reported back into the panel (which shows it and sends nothing).
with tempfile.TemporaryDirectory(prefix="ictus-ui-sound-") as work:
    patch = os.path.join(work, "snd.pd")
    preset = "radius 0.2 \\, tension 4000 \\, mass 0.03 \\, modes 64 \\, t60 1.5 \\, hfdamp 2 \\, volume 0.7"
    with open(patch, "w") as f:
        f.write("#N canvas 0 0 400 300 12;\n#X obj 10 10 loadbang;\n#X msg 10 40 %s;\n"
                "#X obj 10 70 ictus-sound-panel;\n#X obj 10 100 ictus-sound modal;\n"
                "#X msg 200 40 model synth \\, 1 3 0.3 0 \\, model clips \\, 0 2 0.5 90;\n"
                "#X obj 200 140 print report;\n"
                "#X connect 0 0 1 0;\n#X connect 1 0 2 0;\n#X connect 2 0 3 0;\n#X connect 3 2 2 0;\n"
                "#X connect 0 0 4 0;\n#X connect 4 0 3 0;\n#X connect 3 2 5 0;\n" % preset)
    proc = subprocess.run(uitest.PD_BATCH + ["-path", os.path.join(build, "ictus"), "-open", patch,
                                             "-send", "pd dsp 1", "-send", "pd quit"],
                          capture_output=True, text=True, timeout=60, env=uitest.PD_ENV)
log = proc.stdout + proc.stderr
print(log)
check(proc.returncode == 0 and not uitest.error_lines(log) and "ictus-sound-panel:" not in log,
      "[ictus-sound] takes every message of the panel without an error line")
reports = [l.split()[1:] for l in log.splitlines() if l.startswith("report: model")]
check(reports[-2:] == [["model", "synth", "1"], ["model", "clips", "0"]],
      "the model switches are reported back into the panel (%s)" % reports)
