"""[ictus_timetag] passes only well-formed OSC to [oscparse]: a message whose blob argument
declares more bytes than the packet holds is malformed ("blob-size"), whatever the 32-bit
size. The size was rounded up to a multiple of 4 in 32 bits, so a size within 3 of 2^32
wrapped to 0 and the blob passed as empty (oscparse then said "OSC message ended
prematurely"), and one of 2^31 or more became a negative int. Seeded random blob sizes,
small and huge, each after a packet's worth of bytes it may or may not have; checked
against the packet's real length in the test. In batch pd, the bytes sent as lists.

    PYTHONPATH=python python3 tests/pdosc/test_timetag_blob.py --build build
"""
import argparse
import os
import random
import struct

from ictus_tools.checks import check, keep_going, failed
from ictus_tools.oscpacket import osc_string
from ictus_tools.pdrun import Patch, run_pd, make_workdir, send_each_ms

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
args.build = os.path.abspath(args.build)

rng = random.Random(20261202)
cases = []
for i in range(24):
    data = bytes(rng.randrange(256) for _ in range(4 * rng.randint(0, 4)))
    size = rng.choice([rng.randint(0, len(data)), rng.randint(len(data) + 1, 1000),
                       2 ** 32 - rng.randint(1, 3), 2 ** 32 - 4 * rng.randint(1, 4),
                       rng.randint(2 ** 31, 2 ** 32 - 1)])
    if size >= 2 ** 32 - 3 and rng.random() < 0.5:
        data = b""  # the size rounds up to 2^32: nothing after it, as a wrapped 0 would have
    packet = osc_string("/b%d" % i) + osc_string(",b") + struct.pack(">I", size) + data
    padded = (size + 3) // 4 * 4
    cases.append((i, size, len(data), packet, padded == len(data)))

p = Patch(declare="-path %s/ictus" % args.build)
tt = p.obj("ictus_timetag")
parse = p.obj("oscparse")
out = p.obj("print parsed")
info = p.obj("print info")
p.connect(tt, 0, parse, 0)
p.connect(parse, 0, out, 0)
p.connect(tt, 2, info, 0)
send_each_ms(p, tt, ["list " + " ".join(str(b) for b in packet)
                     for _, _, _, packet, _ in cases], tail_ms=10)
rc, log = run_pd(p.text(), os.path.join(args.build, "ictus"), workdir=make_workdir("ictus-blob-"))
keep_going()
check(rc == 0 and "ended prematurely" not in log,
      "pd ran, oscparse never got a short message (exit %d)" % rc)
parsed = [l for l in log.splitlines() if l.startswith("parsed:")]
malformed = [l for l in log.splitlines() if l.startswith("info: malformed")]
for i, size, have, _, fits in cases:
    got = any(l.startswith("parsed: list b%d " % i) or l == "parsed: list b%d" % i
              for l in parsed)
    check(got == fits, "blob of %d bytes declared, %d in the packet: %s" %
          (size, have, "parsed" if got else "refused"))
check(len(malformed) == sum(1 for c in cases if not c[4]),
      "%d packets counted malformed, as many as do not hold their blob" % len(malformed))
if failed():
    raise SystemExit(1)
print("ok")
