"""Pd's Find Last Error finds the box of the abstraction that reported an error ([ictus_error],
docs/externals.md): with [print error: ...] inside, Pd said "no findable error yet".

Each case is a patch with three instances of one abstraction, the middle one given a bad
creation argument or, after load, a bad message. A loadbang then sends `pd finderror`, which
selects the box Pd holds responsible, `cut`s it and saves the patch (menusave). What is
judged is the saved file, read independently of the code under test: exactly the bad
instance's line is gone, its siblings and the rest of the patch kept, and pd's log has the
abstraction's error line. A case that names the wrong box, the box inside the abstraction or
nothing leaves another file.

    PYTHONPATH=python python3 tests/pdosc/test_find_error.py --build build
"""
import argparse
import os
import subprocess
import tempfile

from ictus_tools.checks import check
from ictus_tools.pdrun import PD_BATCH, PD_ENV

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
build = os.path.abspath(args.build)

# (abstraction and good arguments, the bad instance's text, a bad message for it or None,
#  the error line's start); the bad instance is always the middle one (object 3).
CASES = [
    ("ictus-sound clips", "ictus-sound bogus", None,
     "error: ictus-sound: model must be one of"),
    ("ictus-kit-drum 2 render-kit", "ictus-kit-drum 9 render-kit", None, "error: ictus-kit-drum"),
    ("ictus-sound synth", "ictus-sound modal", "volume 5",
     "error: ictus-sound: volume must be in 0..1 (clamped) - got: 5"),
    ("ictus-receive 0", "ictus-receive 70000", None, "error: ictus-receive"),
    # ictus-drum takes no arguments (an extra one is not read): the word only tells the boxes apart
    ("ictus-drum", "ictus-drum bad", "5 3 0.3 0",
     "error: ictus-drum: hand must be 0 (left) 1 (right) 2 (right foot) or 3 (left foot) - got: 5"),
    ("ictus-midifile", "ictus-midifile 10", "open /nonexistent/ictus-no-such.mid",
     "error: ictus-midifile: no MIDI file /nonexistent/ictus-no-such.mid"),
    ("ictus-midifile", "ictus-midifile 10", "start",
     "error: ictus-midifile: unknown message (open play stop loop channel) - got: start"),
    # not a strike list: ictus-sound's own error, not its models' (two lines, from inside)
    ("ictus-sound modal", "ictus-sound synth", "bang",
     "error: ictus-sound: expected a strike list <hand> <velocity m/s> <r/a> <theta deg> - got: "
     "bang"),
    ("ictus-sound modal", "ictus-sound clips", "5",
     "error: ictus-sound: expected a strike list <hand> <velocity m/s> <r/a> <theta deg> - got: 5"),
    ("ictus-drum", "ictus-drum bad", "bang",
     "error: ictus-drum: expected a list <hand> <velocity m/s> <r/a> <theta deg> - got: bang"),
]

for good, bad, message, error_start in CASES:
    with tempfile.TemporaryDirectory(prefix="ictus-finderror-") as work:
        name = "find.pd"
        path = os.path.join(work, name)
        lines = ["#N canvas 0 0 600 400 12;",
                 "#X obj 10 10 loadbang;",
                 "#X msg 10 40 \\; pd finderror \\; pd-%s cut \\; pd-%s menusave \\; pd quit;"
                 % (name, name),
                 "#X obj 10 100 %s;" % good,
                 "#X obj 10 150 %s;" % bad,
                 "#X obj 10 200 %s;" % good]
        if message:
            # [t b b]: the message reaches the middle instance after load, then the find
            lines += ["#X obj 300 10 t b b;", "#X msg 300 40 %s;" % message]
            connects = ["#X connect 0 0 5 0;", "#X connect 5 0 1 0;", "#X connect 5 1 6 0;",
                        "#X connect 6 0 3 0;"]
        else:
            connects = ["#X connect 0 0 1 0;"]
        text = "\n".join(lines + connects) + "\n"
        with open(path, "w") as f:
            f.write(text)
        cmd = PD_BATCH + ["-path", build, "-path", os.path.join(build, "ictus"), path]
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=60, env=PD_ENV,
                              cwd=work)
        log = proc.stdout + proc.stderr
        saved = open(path).read()
        objs = [l for l in saved.splitlines() if l.startswith("#X obj")]
        want = [l for l in text.splitlines() if l.startswith("#X obj") and (" %s;" % bad) not in l]
        what = "[%s]%s" % (bad, " after '%s'" % message if message else "")
        check(proc.returncode == 0 and any(l.startswith(error_start) for l in log.splitlines()),
              "%s: pd reports its error (%s...)" % (what, error_start))
        check("no findable error" not in log and "couldn't find" not in log,
              "%s: Find Last Error has an error to find" % what)
        check(objs == want and saved != text,
              "%s: Find Last Error selects that box and only it (saved: %s)" % (what, objs))
