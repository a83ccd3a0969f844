"""[ictus-view]'s bad input, in the real pd (batch, no window): every malformed pose
or control message prints one line naming the message and what was expected, and
is ignored; well-formed messages print nothing."""
import argparse
import os
import subprocess
import tempfile

from ictus_tools import uitest
from ictus_tools.checks import check

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
build = os.path.abspath(args.build)
if not os.path.isdir("/usr/lib/pd/extra/Gem"):
    uitest.skip_or_fail("Gem is not installed (Debian package gem)", missing_package=True)

CASES = [  # message, the line it must print (None: must print nothing)
    ("body 3 0 1 0 1 0 0 0", None),
    ("stick 1 0 0 0 0 0 0", None),
    ("drum 0 0 1 0 0.2", None),
    ("frame 1", None),
    ("camera side", None),
    ("fps 25", None),
    ("body 25 0 0 0 1 0 0 0", "ictus-view: body index: expected 0 to 19 but got 25"),
    ("body 1.5 0 0 0 1 0 0 0", "ictus-view: body index: expected 0 to 19 but got 1.5"),
    ("body 1 2", "ictus-view: body: expected 8 numbers: index x y z qw qx qy qz"),
    ("stick 3 0 0 0 0 0 0", "ictus-view: stick: expected 7 numbers: hand (0 or 1) tip_xyz butt_xyz"),
    ("stick 0 1", "ictus-view: stick: expected 7 numbers: hand (0 or 1) tip_xyz butt_xyz"),
    ("drum 1 0 0 0 0.2", "ictus-view: drum: expected 5 numbers: id (0) x y z radius"),
    ("camera sideways", "ictus-view: camera: expected front side top or back"),
    ("foo 1", "ictus-view: unknown message: foo 1"),
]
with tempfile.TemporaryDirectory(prefix="ictus-ui-view-") as work:
    patch = os.path.join(work, "vi.pd")
    # one message box: a marker to [r case], then the message to [r viewin], per case
    with open(patch, "w") as f:
        f.write("#N canvas 0 0 400 300 12;\n#X obj 10 10 loadbang;\n#X msg 10 40 %s;\n"
                "#X obj 10 70 r viewin;\n#X obj 10 100 ictus-view;\n#X obj 200 70 r case;\n"
                "#X obj 200 100 print case;\n#X connect 0 0 1 0;\n#X connect 2 0 3 0;\n#X connect 4 0 5 0;\n"
                % " ".join("\\; case %d \\; viewin %s" % (n, m) for n, (m, _) in enumerate(CASES)))
    proc = subprocess.run(uitest.PD_BATCH + ["-path", os.path.join(build, "ictus"), "-open", patch,
                                             "-send", "pd quit"],
                          capture_output=True, text=True, timeout=60, env=uitest.PD_ENV)
lines = [l.strip() for l in (proc.stdout + proc.stderr).splitlines()
         if l.strip().startswith(("ictus-view", "case:", "error", "verbose(1)"))]
print("\n".join(lines))
# group the view's lines by the case marker printed before each message
groups, current = {}, None
for l in lines:
    if l.startswith("case:"):
        current = int(float(l.split()[1]))
        groups[current] = []
    elif current is not None:
        groups[current].append(l)
check(sorted(groups) == list(range(len(CASES))), "every case ran (%d)" % len(groups))
for n, (msg, want) in enumerate(CASES):
    got = groups.get(n, [])
    if want is None:
        check(got == [], "%r prints nothing" % msg)
    else:
        check(got == [want], "%r -> %r (got %r)" % (msg, want, got))
