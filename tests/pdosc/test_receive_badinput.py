"""[ictus-receive]'s control inlet given a bad `connect` or a bare `latency` (docs/pd-osc.md):
an error line from ictus-receive that says what it takes and quotes what it got, and the
message is ignored. A missing or non-whole port, one outside 1..65535, a number for the
host, extra values: they reached [netsend] ("netsend: bad connect arguments", "bad host or
port?"), which names neither ictus-receive nor the parameter; a bare `latency` reached a
[latency $1( box ("$1: argument number out of range"). Seeded random bad messages; a good
`connect localhost PORT` among them connects (the connection outlet says 1).

    PYTHONPATH=python python3 tests/pdosc/test_receive_badinput.py --build build
"""
import argparse
import os
import random

from ictus_tools.checks import check, keep_going, failed
from ictus_tools.pdrun import (Patch, check_bad_messages, error_lines, free_udp_port, run_pd,
                               make_workdir, send_each_ms)

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
args.build = os.path.abspath(args.build)

rng = random.Random(20261202)


def bad_port():
    return rng.choice(["0", "-%d" % rng.randint(1, 9000), str(rng.randint(65536, 10 ** 6)),
                       "%.2f" % rng.uniform(1.01, 65534.99), "foo", "nan"])


BAD = []
for _ in range(4):
    BAD.append("connect localhost %s" % bad_port())
    BAD.append("connect %d %d" % (rng.randint(1, 1000), rng.randint(1, 65535)))
    BAD.append("connect localhost %d %s" % (rng.randint(1, 65535), rng.choice(["9", "foo"])))
    BAD.append(rng.choice(["connect", "connect localhost", "latency"]))
GOOD = "connect localhost %d" % free_udp_port()

p = Patch(declare="-path %s/ictus" % args.build)
rec = p.obj("ictus-receive")
state = p.obj("print connection")
p.connect(rec, 4, state, 0)
send_each_ms(p, rec, BAD + [GOOD])
rc, log = run_pd(p.text(), os.path.join(args.build, "ictus"), workdir=make_workdir("ictus-rcv-bad-"))
keep_going()
errors = error_lines(log)
check(rc == 0, "pd ran (exit %d)" % rc)
check_bad_messages(errors, "ictus-receive", BAD)
check(len(errors) == len(BAD), "one error line per bad message (%d for %d)" % (len(errors), len(BAD)))
check("connection: 1" in log, "'%s' connects" % GOOD)
if failed():
    raise SystemExit(1)
print("ok")
