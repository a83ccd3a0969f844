"""Creation arguments of the abstractions, as a user types them: a bad one gets an error line
naming the abstraction and the argument, and is clamped or refused; it never reaches a vanilla
object inside as something else.

[ictus-out~ WIDTH] (docs/pd-osc.md, "The output stage"): a cosine into the left inlet only, so
the outlets read the width's a = (1 + W) / 2 and b = (1 - W) / 2. A width out of 0..1 is
clamped with the width's error line; a symbol leaves the default 1; extra arguments are
ignored, said so (they once reached the [clip 0 1] inside as its bounds: [ictus-out~ 0.2 9]
mixed with a = 5, b = -4, and no later width message could bring it back).

    PYTHONPATH=python python3 tests/pdosc/test_abstraction_args.py --build build
"""
import argparse
import os

import numpy as np

from ictus_tools.checks import check, keep_going, failed
from ictus_tools.pdrun import Patch, make_workdir, read_wav_float, recorder, run_pd

SR, SECONDS, A = 48000, 0.2, 0.1


def out_args(build):
    # (arguments, width message sent at load or None, expected a and b, error lines expected)
    cases = [
        ("0.2", None, 0.2, []),
        ("0.2 9", None, 0.2, ["ictus-out~: takes one argument"]),
        ("0.2 9", "width 0", 0.0, ["ictus-out~: takes one argument"]),
        ("5", None, 1.0, ["ictus-out~: width must be in 0..1 (clamped) - got: 5"]),
        ("-1", None, 0.0, ["ictus-out~: width must be in 0..1 (clamped) - got: -1"]),
        ("foo", None, 1.0, ["ictus-out~: the argument WIDTH must be a number"]),
        ("foo", "width 0.5", 0.5, ["ictus-out~: the argument WIDTH must be a number"]),
    ]
    p = Patch()
    osc = p.obj("osc~ 50")
    amp = p.obj("*~ %g" % A)
    p.connect(osc, 0, amp, 0)
    lb = p.obj("loadbang")
    tables = []
    for i, (arg, msg, _, _) in enumerate(cases):
        o = p.obj("ictus-out~ %s" % arg)
        p.connect(amp, 0, o, 0)
        if msg:
            m = p.msg(msg)
            p.connect(lb, 0, m, 0)
            p.connect(m, 0, o, 4)
        tables += [(o, 0, "l%d" % i), (o, 1, "r%d" % i)]
    work = make_workdir("ictus-pdosc-args-")
    wav = os.path.join(work, "out.wav")
    recorder(p, tables, SECONDS, SR, wav)
    rc, log = run_pd(p.text(), os.path.join(build, "ictus"), sr=SR, workdir=work)
    check(rc == 0, "pd ran (rc %d)" % rc)
    check("clip:" not in log, "no argument reaches the [clip] inside: %s" %
          [l for l in log.splitlines() if "clip:" in l])
    y, _ = read_wav_float(wav)
    peak = np.abs(y[len(y) // 2:]).max(axis=0)
    for i, (arg, msg, w, errors) in enumerate(cases):
        a, b = (1 + w) / 2, (1 - w) / 2
        what = "[ictus-out~ %s]%s" % (arg, " then %s" % msg if msg else "")
        check(abs(peak[2 * i] - A * a) < 1e-4 and abs(peak[2 * i + 1] - A * b) < 1e-4,
              "%s mixes with width %g: left %.5f (want %.5f), right %.5f (want %.5f)"
              % (what, w, peak[2 * i], A * a, peak[2 * i + 1], A * b))
        for e in errors:
            check(e in log, "%s: error line '%s'" % (what, e))
    lines = [l for l in log.splitlines() if l.startswith("error:")]
    want = sum(len(c[3]) for c in cases)
    check(len(lines) == want, "%d error lines, one per bad argument (got %d: %s)"
          % (want, len(lines), lines))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    build = os.path.abspath(ap.parse_args().build)
    keep_going()
    out_args(build)
    if failed():
        raise SystemExit(1)
    print("ok")


if __name__ == "__main__":
    main()
