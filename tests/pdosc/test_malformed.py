"""Malformed and fuzzed packets sent to [ictus-receive]'s port are dropped whole, counted
(info outlet `malformed <count> <reason>`), reported with an error naming
ictus_timetag (the first 5 only), and break nothing: strikes sent afterwards
still start at their timetag within 1 ms (or, handled after it by a stalled
machine, fire at once and are reported late with their lateness, as in
test_realtime.py). A well-formed /ictus/strike with
other type tags than docs/osc.md fixes (wrong count, floats for ints, a string)
is refused too: ictus-receive tells ictus_timetag `expect /ictus/strike ...`."""
import argparse
import os
import random
import re
import socket
import struct
import time

from ictus_tools.oscpacket import bundle, message, now, osc_string, strike, timetag
from ictus_tools.rtpd import (Listener, build_patch, free_udp_port, quit_pd,
                              start_pd, wait_for_ticks, wait_records, unexplained_late,
                              wall_of_logical)
from ictus_tools.checks import check, inconclusive

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
build = os.path.abspath(args.build)

good = bundle(timetag(now() + 100.0), strike(1, 0))
bad = [b"garbage!", b"hello world;", b"\xff" * 4000, b"/ictus/strike",  # no NUL, size % 4
       osc_string("/ictus/strike") + osc_string(",q") + b"\0" * 4,      # unknown type tag
       osc_string("/ictus/strike") + osc_string(",iiii") + b"\0" * 8,   # arguments short
       osc_string("/ictus/strike") + osc_string(",i") + b"\0" * 8,      # trailing bytes
       osc_string("/ictus/x") + osc_string(",s") + b"abcd",             # string without NUL
       osc_string("/ictus/x") + osc_string(",b") + struct.pack(">i", 1000),  # blob too long
       b"#bundle\0" + timetag(now()) + struct.pack(">i", 1000) + b"/a\0\0",    # element too long
       b"#bundle\0" + timetag(now()) + struct.pack(">i", 3) + b"/a\0\0",       # size % 4
       b"#bundle\0" + timetag(now()) + struct.pack(">i", -8) + b"/a\0\0"]      # negative size
nested = message("/ictus/pong", "")
for _ in range(10):  # deeper than ictus_timetag's limit of 8
    nested = bundle(timetag(now()), nested)
bad.append(nested)
# 19 arguments but not the fixed type tags of /ictus/strike (docs/osc.md), and the
# 17 and 18 of the layouts before stick_mass_kg and before stick_tip
bad.append(message("/ictus/strike", "iiiiffffffffffffffi".replace("i", "f"), *range(19)))
bad.append(message("/ictus/strike", "iiiiffffffffffffffs", *range(18), "x"))
bad.append(message("/ictus/strike", "iiiifffffffffffff", *range(17)))
bad.append(message("/ictus/strike", "iiiiffffffffffffff", *range(18)))
bad.append(bundle(timetag(now()), message("/ictus/strike", "ii", 1, 2)))  # 2 arguments
# every truncation of a good strike bundle, except 16 bytes (a valid empty bundle)
bad += [good[:n] for n in range(1, len(good)) if n != 16]
# random bit flips in the framing of a strike bundle (header, timetag, element
# size, address): whatever they become, pd must carry on. Their strikes carry
# seq 999 and are ignored below.
fuzz_base = bytearray(bundle(timetag(now()), strike(999, 0)))
rng = random.Random(7)
fuzz = []
for _ in range(300):
    b = bytearray(fuzz_base)
    for _ in range(rng.randint(1, 3)):
        i = rng.randrange(0, 36)
        b[i] ^= 1 << rng.randrange(8)
    fuzz.append(bytes(b))

SENTINEL = message("/ictus/strike", "ii", 3, 4)
TAGGED_BAD = 8  # the strikes of `bad` refused for their type tags (checked below)
HANDSHAKE_S = 30.0
# pd's own deadline: the test ends it by handshake (quit_pd) once the good strikes
# came out (a fixed 5 s ended pd before the last two under a loaded ASan run)
PD_DEADLINE_S = 600.0


def tagged(malformed):
    return sum(1 for m in malformed if m[3] == "unexpected-type-tags")


def fired(records):
    """The strikes that came out, by sequence number (999: the fuzz base)."""
    return {int(a[10]): a for _, a in records if a[0] == "fire" and int(a[10]) != 999}


def wait_for_malformed(done, timeout=HANDSHAKE_S):
    """Polls pd's reports until done(the `malformed` records so far), or the deadline
    (inconclusive then if this script's listener lost a report: the count may be it)."""
    t0 = time.time()
    while time.time() - t0 < timeout:
        if done([a for _, a in reports.records()
                 if a[0] == "info" and len(a) > 3 and a[1] == "malformed"]):
            return True
        time.sleep(0.005)
    reports.require_intact()
    return False


reports = Listener()
pd_port, fudi_port = free_udp_port(), free_udp_port()
proc, work = start_pd(build_patch(build, pd_port, reports.port, PD_DEADLINE_S,
                                  fudi_in_port=fudi_port), build)
out = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
sent = {}
try:
    check(wait_for_ticks(reports), "pd runs in real time and reports ticks")
    # Ten packets at a time, each ten waited for by handshake: pd's count of the
    # malformed ones, reported to this script (a paced flood, 5 ms between tens, lost
    # packets under a loaded ASan run: a socket's buffer overflows when pd or this
    # script's listener is off the CPU, and a count was missing).
    for i in range(0, len(bad), 10):
        for packet in bad[i:i + 10]:
            out.sendto(packet, ("127.0.0.1", pd_port))
        n = min(i + 10, len(bad))
        check(wait_for_malformed(lambda m: len(m) >= n), "pd counted the first %d malformed "
              "packets within %.0f s" % (n, HANDSHAKE_S))
    out.sendto(good[:16], ("127.0.0.1", pd_port))
    # The fuzzed ones may be well formed or not: each ten is followed by a strike with
    # the wrong type tags (no bit flip of the framing makes one), waited for as above.
    for i in range(0, len(fuzz), 10):
        for packet in fuzz[i:i + 10]:
            out.sendto(packet, ("127.0.0.1", pd_port))
        out.sendto(SENTINEL, ("127.0.0.1", pd_port))
        n = TAGGED_BAD + i // 10 + 1
        check(wait_for_malformed(lambda m: tagged(m) >= n), "pd took the fuzzed packets "
              "%d-%d within %.0f s" % (i + 1, min(i + 10, len(fuzz)), HANDSHAKE_S))
    # All ten at once, the first 0.5 s ahead: what is judged is pd after the
    # flood, not this sender's pacing (paced 50 ms ahead, as the daemon does, a
    # loaded CI run stalled this script past three strikes' lookahead; the
    # daemon's lookahead is test_realtime.py's).
    t = now() + 0.5
    for seq in range(1, 11):
        out.sendto(bundle(timetag(t), strike(seq, seq % 2)), ("127.0.0.1", pd_port))
        sent[seq] = t
        t += 0.04
    # not required: the checks below say which strikes are missing, if any
    wait_records(reports, lambda r: len(fired(r)) >= len(sent), "the 10 good strikes",
                 timeout=HANDSHAKE_S, required=False)
    log = quit_pd(proc, fudi_port)
finally:
    if proc.poll() is None:
        proc.kill()
        proc.communicate()
    reports.close()

records = reports.records()
reports.require_intact()
print(log)
check(proc.returncode == 0, "pd exited normally (%s)" % proc.returncode)
malformed = [a for _, a in records if a[0] == "info" and len(a) > 1 and a[1] == "malformed"]
check(len(malformed) >= len(bad) and malformed[len(bad) - 1][2] == len(bad)
      and [m[2] for m in malformed] == list(range(1, len(malformed) + 1)),
      "each of the %d malformed packets counted once (then %d of %d fuzzed ones, and %d "
      "strikes with the wrong type tags after each ten)"
      % (len(bad), len(malformed) - len(bad) - len(fuzz) // 10, len(fuzz), len(fuzz) // 10))
lines = [l for l in log.splitlines() if l.strip()]
timetag_errors = [l for l in lines if "ictus_timetag: malformed OSC packet" in l]
check(len(timetag_errors) == 5, "the first 5 malformed packets are reported by name (%d)"
      % len(timetag_errors))
# the five new ones, and the ,q / ,iiii / ,i strikes above (caught by their tags first)
check(sum(1 for m in malformed[:len(bad)] if m[3] == "unexpected-type-tags") == 8,
      "strikes with other type tags than ,iiiiffffffffffffffi are refused (unexpected-type-tags)")
# Pd's own note that a send of the report path ([netsend] to this test) took
# long ("verbose(3): netsend/netreceive: blocked 8 msec": the process was off the
# CPU, once under a loaded ASan run) says nothing about the packets: not counted.
others = [l for l in lines if l not in timetag_errors
          and not re.match(r"verbose\(\d\): netsend/netreceive: blocked \d+ msec$", l.strip())]
check(not others, "nothing else in pd's log: %s" % others)
offset = wall_of_logical(records)
fires = fired(records)
check(sorted(fires) == sorted(sent), "exactly the 10 good strikes came out: %s" % sorted(fires))
# As in test_realtime.py: a strike pd handled after its time (the sender or pd
# stalled past its lookahead) fires
# at once by design and is reported late with its lateness (docs/pd-osc.md).
# Each strike more than 1 ms off must be one of those, its report's lateness its
# own error within 1 ms, and most must be on time, or the run judged too little
# (inconclusive: CTest's command, ictus_tools.retry, runs it again).
errors = {s: (offset + fires[s][1] / 1000.0 - sent[s]) * 1000.0 for s in sent}
reported = [a[2] for _, a in records if a[0] == "info" and len(a) > 2 and a[1] == "late"]
unexplained = unexplained_late([(s, e) for s, e in sorted(errors.items()) if abs(e) > 1.0],
                               reported, 1.0)
on_time = [abs(e) for e in errors.values() if abs(e) <= 1.0]
check(not unexplained,
      "after the malformed packets, strikes start at their timetag within 1 ms (worst %.3f ms, "
      "%d of %d), or were handled late and reported so (unexplained: %s)"
      % (max(on_time) if on_time else float("inf"), len(on_time), len(sent), unexplained))
if len(on_time) < len(sent) - 2:
    inconclusive("%d of %d strikes on time, the rest handled late and reported so: too few to "
                 "judge" % (len(on_time), len(sent)))
