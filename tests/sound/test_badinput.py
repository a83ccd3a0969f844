"""Bad input to the sound abstractions is refused or clamped with an error line
naming the object and the parameter, and never makes NaN or a crash:
velocity <= 0 (stroke ignored by clips and synth; contact~ refuses it in modal),
volume out of 0..1 and fade out of 0..1000 (clamped), an unknown model,
head parameters out of membrane~'s ranges (clamped by the synth, reported by
membrane~). A clips abstraction without its clip file says which file is missing."""
import argparse
import os
import shutil
import subprocess

import numpy as np

from ictus_tools.checks import check
from ictus_tools.soundrun import (PD_BATCH, PD_ENV, RENDER, make_workdir, read_wav_float,
                                  write_events)

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
build = os.path.abspath(args.build)
work = make_workdir("ictus-sound-bad-")


def run(model, items, head, seconds=0.6):
    ev = os.path.join(work, "ev-%s.txt" % model)
    wav = os.path.join(work, "out-%s.wav" % model)
    write_events(ev, items, head=head)
    cmd = PD_BATCH + ["-r", "48000", "-path", os.path.join(build, "ictus"), "-open", RENDER,
                      "-send", "render-model %s" % model, "-send", "render-file %s" % ev, "-send",
                      "render-out %s" % wav, "-send", "render-seconds %g" % seconds]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=60, env=PD_ENV)
    x, _ = read_wav_float(wav)
    return proc.returncode, proc.stdout + proc.stderr, x


def open_lines(name, body):
    """Opens a patch of the objects in body (its #X lines, after the canvas) in pd -batch and
    quits: (return code, the log)."""
    path = os.path.join(work, name)
    with open(path, "w") as f:
        f.write("#N canvas 0 0 400 300 12;\n" + body)
    proc = subprocess.run(PD_BATCH + ["-path", os.path.join(build, "ictus"), "-open", path, "-send",
                                      "pd quit"],
                          capture_output=True, text=True, timeout=60, env=PD_ENV)
    return proc.returncode, proc.stdout + proc.stderr


for model in ("clips", "synth", "modal"):
    head = ["render-drum volume 3", "render-drum fade -5", "render-drum model guitar",
            "render-drum model 7", "render-drum radius -1", "render-drum tension 1e9",
            "render-drum t60 0"]
    # the head is put back in range before the strokes that must sound
    items = [(50.0, 0, 0.0, 0.3, 0.0), (100.0, 1, -2.0, 0.3, 0.0), (150.0, "render-drum radius 0.178"),
             (150.0, "render-drum tension 3000"), (150.0, "render-drum t60 0.3"), (200.0, 0, 2.0, 1.7, 30.0),
             (300.0, 1, 60.0, 0.3, 30.0)]
    rc, log, x = run(model, items, head)
    print(log)
    check(rc == 0 and np.all(np.isfinite(x)), "%s: pd ran and the output is finite" % model)
    check("error: ictus-sound: volume must be in 0..1 (clamped) - got: 3" in log
          and "error: ictus-sound: fade must be in 0..1000 ms (clamped) - got: -5" in log
          and "error: ictus-sound: model must be one of clips synth modal 0 1 2 - got: guitar" in log
          and "error: ictus-sound: model must be one of clips synth modal 0 1 2 - got: 7" in log,
          "%s: volume, fade and model errors name ictus-sound and the value" % model)
    check("membrane~: radius" in log and "membrane~: tension" in log,
          "%s: head parameters out of range are reported by membrane~" % model)
    check("error: ictus-sound-synth: radius (m) must be in 0.01..2 (clamped) - got: -1" in log
          and "error: ictus-sound-synth: t60 (s) must be in 0.005..60 (clamped) - got: 0" in log,
          "%s: ... and clamped by the synth, naming the parameter" % model)
    y = np.abs(x).max(axis=1)
    if model != "modal":
        check(("error: ictus-sound-%s: velocity must be > 0 m/s (stroke ignored) - got: 0" % model) in log
              and ("error: ictus-sound-%s: velocity must be > 0 m/s (stroke ignored) - got: -2" % model) in log,
              "%s: zero and negative velocities are refused, naming the object" % model)
        check(y[:int(0.2 * 48000)].max() == 0, "%s: refused strokes make no sound" % model)
    else:
        check("contact~" in log, "modal: contact~ refuses the bad velocities")
    check(y[int(0.2 * 48000):].max() > 0.01 and y.max() < 10.0,
          "%s: r/a 1.7 and 60 m/s (clamped to 50) play, finite (peak %.3f < 10)" % (model, y.max()))

# A clips abstraction whose clip file is missing names the file.
lib = os.path.join(work, "lib")
os.makedirs(lib)
# the library folder without its clips: the two abstractions and [ictus_error], whose
# binary reports their errors
errors_binary = [f for f in os.listdir(os.path.join(build, "ictus"))
                 if f.startswith("ictus_error.") and not f.endswith(".pd")]
for f in ["ictus-sound-clips.pd", "ictus-sound-clips-voice.pd"] + errors_binary:
    shutil.copy(os.path.join(build, "ictus", f), lib)
with open(os.path.join(lib, "t.pd"), "w") as f:
    f.write("#N canvas 0 0 400 300 12;\n#X obj 10 10 ictus-sound-clips;\n")
proc = subprocess.run(PD_BATCH + ["-open", os.path.join(lib, "t.pd"), "-send", "pd quit"],
                      capture_output=True, text=True, timeout=60, env=PD_ENV)
log = proc.stdout + proc.stderr
print(log)
check(proc.returncode == 0 and "error: ictus-sound-clips: clips/ictus-clips.wav" in log,
      "a missing clip file is named in an error line")

# Every membrane~ message [ictus-sound] forwards to its models (docs/sound.md: "anything else:
# to the modal model's membrane~") is taken without a word by the models it does not concern:
# the synth said "unknown message" for tensionmod, radiation, lossfactor, patch, cascade,
# bending, vonkarman, openness, edgedamp and wires, whatever the model playing.
good = ["tensionmod 0.5", "radiation 0.5", "lossfactor 0.002", "airmass 0", "patch 0.007", "cascade 1",
        "bending 9", "vonkarman 0", "openness 1", "edgedamp 0", "wires on", "wires off",
        "preset tom", "hfdamp 1", "modes 128", "gain 0.16", "pickup 1 0.5 0", "position 0.3 0"]
MESSAGES = ("#X obj 10 10 ictus-sound modal;\n#X obj 10 40 loadbang;\n#X msg 10 70 %s;\n"
            "#X connect 1 0 2 0;\n#X connect 2 0 0 0;\n")
rc, log = open_lines("forward.pd", MESSAGES % " \\, ".join(good))
bad = [l for l in log.splitlines() if "error" in l]
check(rc == 0 and not bad,
      "membrane~'s messages through [ictus-sound modal]: no error line (%s)" % bad)

# A symbol where a number goes is refused by name: it reached a [t f f f] inside ictus-sound
# (volume, fade), ictus-sound-synth (radius, tension, density, mass, t60) or the hoop of
# ictus-drum (t60), whose "trigger: generic messages ..." named none of them.
words = {"volume foo": "error: ictus-sound: volume must be a number in 0..1 - got: foo",
         "fade foo": "error: ictus-sound: fade must be a number in 0..1000 ms - got: foo"}
for name in ("radius", "tension", "density", "mass", "t60"):
    words["%s foo" % name] = "error: ictus-sound-synth: expected a number for: %s foo" % name
_, log = open_lines("symbols.pd", MESSAGES % " \\, ".join(words))
for msg, line in words.items():
    check(line in log, "[ictus-sound modal] %s: '%s'" % (msg, line))
check("trigger:" not in log, "no line from a [trigger] inside: %s"
      % [l for l in log.splitlines() if "trigger:" in l])

# Creation arguments: [ictus-sound MODEL] takes one; more are said by name and ignored (the
# model still set), one or none says nothing.
_, log = open_lines("args.pd", "#X obj 10 10 ictus-sound synth extra 3;\n"
                    "#X obj 10 40 ictus-sound modal;\n#X obj 10 70 ictus-sound;\n")
errors = [l for l in log.splitlines() if "error" in l]
check(errors == ["error: ictus-sound: takes one argument (the model) - extra arguments ignored - "
                 "got: extra 3"], "extra arguments said once, by name; one or none silent: %s"
      % errors)
