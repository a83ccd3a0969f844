"""Real time: pd without -batch (its clock follows the system clock) runs
[ictus-receive]; this script sends hand-built OSC bundles over loopback with
timetag = now + lookahead and checks that each strike comes out at the logical
time that corresponds to its timetag, within 1 ms. The logical-to-wall mapping
is measured here, from pd's own tick reports (ictus_tools.rtpd), not taken from the
code under test. The reports reach this script some transit time after pd
sent them, so that mapping is late by the transit; round trips (`probe`,
echoed by the patch) bound it: the transit is at most the shortest round trip,
and each strike's error is known to lie in [e - rtt_min, e]. Also: strike fields come out in the documented order, a
late bundle fires at once and is counted, pose/reply messages pass through,
and control messages reach the daemon side as /ictus/<name> OSC. The
receiver starts without a port and gets `listen PORT` from its inlet.
With --slow-load, the patch creates a large array after [ictus-receive] (tens of
ms of loading before Pd's scheduler ties logical time to the wall clock): the
mapping must not take the wall clock at creation for logical time 0."""
import argparse
import json
import os
import socket
import struct
import time

from ictus_tools.oscpacket import bundle, message, now, strike, timetag, IMMEDIATE
from ictus_tools.rtpd import (Listener, build_patch, free_udp_port, quit_pd,
                              start_pd, wait_for_ticks, wait_records, unexplained_late,
                              wall_of_logical)
from ictus_tools.checks import check, inconclusive
from ictus_tools.pdrun import error_lines

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
ap.add_argument("--slow-load", action="store_true")
args = ap.parse_args()
build = os.path.abspath(args.build)

HALF = 12  # strikes sent as planned per half, before and after 'latency 10'
MAX_PER_HALF = 2 * HALF
SENDER_SLACK_S = 0.020  # sent later than planned by more: this script stalled
LOOKAHEAD_S = 0.060
SPACING_S = 0.045
SECONDS = 600.0  # pd's own deadline: the test ends it by handshake (quit_pd)
LATENCY_MS = 10.0
LATE_OVERDUE_S = 1.0

reports = Listener()
ctl = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
ctl.bind(("127.0.0.1", 0))
ctl.settimeout(0.1)
pd_port, fudi_port = free_udp_port(), free_udp_port()
patch = build_patch(build, pd_port, reports.port, SECONDS, ctl_port=ctl.getsockname()[1],
                    control_msgs=["tempo 96", "grip french", "ping"], listen_later=True,
                    fudi_in_port=fudi_port, ballast=30000000 if args.slow_load else 0)
proc, work = start_pd(patch, build)
out = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
try:
    check(wait_for_ticks(reports), "pd runs in real time and reports ticks")
    # ictus-receive listens from 300 ms on ('listen PORT'); meanwhile
    # ictus_timetag collects clock samples (every 2 ms)
    time.sleep(0.6)
    sent = {}  # seq -> (timetag_s, hand, velocity, r_over_a, theta, stick_mass_kg)
    second_half = 1 << 30  # the first strike after 'latency 10' 
    probes = {}  # k -> wall time sent

    def probe():
        k = len(probes) + 1
        probes[k] = now()
        out.sendto(b"probe %d;\n" % k, ("127.0.0.1", fudi_port))

    for _ in range(20):
        probe()
        time.sleep(0.01)
    # Each half (latency 0, then latency 10) needs HALF strikes whose bundle left
    # this script as planned, LOOKAHEAD_S before its time (within SENDER_SLACK_S):
    # only those judge pd. A strike this script sent late (a loaded CI run stalled
    # it 250 ms, and four strikes went out back to back after their time) must
    # still fire at once and be reported late, but says nothing about pd's
    # scheduling: another is sent in its place, MAX_PER_HALF strikes at most.
    seq = 0
    planned = set()  # the strikes whose bundle left as planned
    for half in (0, 1):
        if half:
            # from here on, an audio output latency of 10 ms is subtracted. Sent
            # once pd has reported every strike so far fired (a handshake): pd
            # polls its sockets in the order they opened, so after a stall of pd
            # the latency could be handled before an older strike still queued,
            # which then started 10 ms early (seen under a loaded ASan run).
            wait_records(reports, lambda r: set(sent) <= {int(a[10]) for _, a in r
                                                          if a[0] == "fire"},
                         "the first half's %d strikes fired" % len(sent), timeout=30.0)
            out.sendto(b"latency %g;\n" % LATENCY_MS, ("127.0.0.1", fudi_port))
            time.sleep(0.05)
            second_half = seq + 1
        t_next = now() + LOOKAHEAD_S
        for _ in range(MAX_PER_HALF):
            if sum(1 for s in planned if (s >= second_half) == bool(half)) >= HALF:
                break
            seq += 1
            # send each bundle LOOKAHEAD_S before its time, as the daemon does
            while now() < t_next - LOOKAHEAD_S:
                time.sleep(0.0005)
            hand, vel, ra, th = seq % 2, 0.5 + 0.25 * seq, 0.01 * seq, 7.0 * seq
            mass = 0.01 + 0.001 * seq
            out.sendto(bundle(timetag(t_next), strike(seq, hand, vel, ra, th, stick_mass_kg=mass,
                                                              stick_tip=seq % 4)),
                       ("127.0.0.1", pd_port))
            if now() - (t_next - LOOKAHEAD_S) <= SENDER_SLACK_S:
                planned.add(seq)
            sent[seq] = (t_next, hand, vel, ra, th, mass)
            t_next += SPACING_S
            time.sleep(0.005)
            probe()
    time.sleep(0.2)
    # a bundle a second overdue: fires at once, counted as late. Pd's logical
    # clock may lag the wall clock on a loaded machine (a sanitizer build under
    # load lagged 40 ms here), and a bundle less overdue than that lag is on
    # time for pd, not late; a second is well past any lag seen.
    late_seq = 1000
    t_late = now() - LATE_OVERDUE_S
    out.sendto(bundle(timetag(t_late), strike(late_seq, 1)), ("127.0.0.1", pd_port))
    t_late_sent = now()
    # pass-through: pose bundle (immediate), reply, error, pong
    out.sendto(bundle(IMMEDIATE, message("/ictus/pose/frame", "if", 42, 1.5),
                      message("/ictus/pose/body", "iffffffff", 3, 1, 2, 3, 4, 5, 6, 7, 8)),
               ("127.0.0.1", pd_port))
    out.sendto(message("/ictus/reply", "ss", "tempo", "ok"), ("127.0.0.1", pd_port))
    out.sendto(message("/ictus/error", "ss", "grip", "unknown grip"), ("127.0.0.1", pd_port))
    out.sendto(message("/ictus/pong", ""), ("127.0.0.1", pd_port))
    control = []
    t0 = time.time()
    while time.time() - t0 < 1.0:
        try:
            control.append(ctl.recv(65536))
        except socket.timeout:
            pass
    # not required: the checks below say what is missing, if anything
    wait_records(reports, lambda r: set(sent) | {late_seq} <= {int(a[10]) for _, a in r
                                                                if a[0] == "fire"}
                 and sum(a[0] == "pose" for _, a in r) >= 2
                 and sum(a[0] == "reply" for _, a in r) >= 3,
                 "every strike, pose and reply", timeout=30.0, required=False)
    log = quit_pd(proc, fudi_port)
finally:
    if proc.poll() is None:
        proc.kill()
        proc.communicate()
    reports.close()

records = reports.records()
reports.require_intact()
with open(os.path.join(work, "reports.json"), "w") as f:  # kept with the work folder on failure
    json.dump({"records": records, "sent": sent, "probes": probes}, f)
check(proc.returncode == 0 and not error_lines(log), "pd ran cleanly: %s" % error_lines(log))
offset = wall_of_logical(records)
rtts = [t - probes[int(a[2])] for t, a in records
        if a[0] == "probe" and len(a) > 2 and int(a[2]) in probes]
check(len(rtts) >= len(probes) // 2, "probes came back (%d of %d)" % (len(rtts), len(probes)))
rtt_ms = min(rtts) * 1000.0
print("round trip to pd (ms): min %.3f median %.3f" % (rtt_ms, sorted(rtts)[len(rtts) // 2] * 1e3))
check(rtt_ms < 3.0, "the loopback round trip (%.3f ms) is short enough to judge 1 ms" % rtt_ms)
fires = {int(a[10]): (t, a) for t, a in records if a[0] == "fire"}
check(set(sent) <= set(fires), "all %d strikes came out (got %d)" % (len(sent), len(fires)))
errors_ms, arrival_ms = [], []
for seq, (tag, hand, vel, ra, th, mass) in sorted(sent.items()):
    t_arr, a = fires[seq]
    logical_ms = a[1]
    fields = a[2:]
    check(len(fields) == 19, "strike %d has 19 fields" % seq)
    # documented order: hand velocity r/a theta mass force bounce drum seq time x y vt J dur
    # dx dy dz tip
    check(abs(fields[0] - hand) < 1e-6 and abs(fields[1] - vel) < 1e-4
          and abs(fields[2] - ra) < 1e-5 and abs(fields[3] - th) < 1e-3
          and abs(fields[4] - mass) < 1e-7 and abs(fields[5] - 50.0) < 1e-3 and fields[6] == 0
          and fields[8] == seq and abs(fields[17] + 1.0) < 1e-6 and fields[18] == seq % 4,
          "strike %d fields in the documented order: %s" % (seq, fields))
    latency_ms = LATENCY_MS if seq >= second_half else 0.0
    errors_ms.append((offset + logical_ms / 1000.0 - tag) * 1000.0 + latency_ms)
    arrival_ms.append((t_arr - tag) * 1000.0)
# the mapping is late by the reports' transit, in [0, rtt]: the error of each
# strike lies in [e - rtt, e]; the nearest it can be to 0 is what is judged
worst = max(max(e - rtt_ms, 0.0) if e > 0 else -e for e in errors_ms)
print("onset - timetag (ms), per strike, before the transit (0..%.3f ms) is taken off: %s"
      % (rtt_ms, " ".join("%.3f" % e for e in errors_ms)))
print("report arrival - timetag (ms): min %.3f median %.3f max %.3f"
      % (min(arrival_ms), sorted(arrival_ms)[len(arrival_ms) // 2], max(arrival_ms)))
lates = [a for _, a in records if a[0] == "info" and len(a) > 1 and a[1] == "late"]
# A strike pd handled after its time (the sender or pd stalled past the 60 ms
# lookahead on a loaded machine) is not on time by design: it fires at once and
# is reported late with its lateness (docs/pd-osc.md). Each strike more than
# 1 ms late must be one of those, the report's lateness its own error within
# 1 ms; and most of the strikes this script sent as planned must be on time, or
# the run judged too little: it is inconclusive and CTest's command
# (ictus_tools.retry) runs it again.
judged = [max(e - rtt_ms, 0.0) if e > 0 else -e for e in errors_ms]
late_strikes = [(seq, e) for seq, e, j in zip(sorted(sent), errors_ms, judged) if j > 1.0]
unexplained = unexplained_late(late_strikes, [a[2] for a in lates], 1.0 + rtt_ms)
on_time = [j for seq, j in zip(sorted(sent), judged) if seq in planned and j <= 1.0]
worst = max(on_time) if on_time else float("inf")
if late_strikes:
    print("strikes handled late and reported late (seq, ms): %s" % late_strikes)
if len(planned) < len(sent):
    print("strikes this script sent later than planned (not judged on time): %s"
          % sorted(set(sent) - planned))
check(not unexplained,
      "every strike starts at its timetag (minus 10 ms for the second half, after 'latency 10') "
      "within 1 ms (worst %.3f ms, %d of the %d sent as planned), or was handled late and "
      "reported so (%d; unexplained: %s)"
      % (worst, len(on_time), len(planned), len(late_strikes), unexplained))
if len(planned) < 2 * HALF:
    inconclusive("this script sent only %d of %d strikes as planned: it stalled past the "
                 "lookahead again and again; too few to judge" % (len(planned), len(sent)))
if len(on_time) < 2 * HALF - 4:
    inconclusive("%d of %d strikes on time, the rest handled late and reported so: the machine "
                 "stalled past the lookahead; too few to judge" % (len(on_time), len(planned)))

t_arr, a = fires.get(late_seq, (None, None))
check(a is not None, "the late bundle fired")
late_fire = offset + a[1] / 1000.0
# pd handles the packet at its logical "now", which may lag the wall clock: the
# lag at that moment shows in the fire report's own arrival (t_arr - late_fire,
# the transit included). Fired at once: no later than 10 ms after sending, and no
# earlier than the sending minus that lag.
lag_ms = max(0.0, (t_arr - late_fire) * 1e3 - rtt_ms)
fired_ms = (late_fire - t_late_sent) * 1e3
check(-10.0 - lag_ms < fired_ms < 10.0,
      "the late bundle fired on arrival (%.2f ms after sending; pd's clock %.2f ms behind the "
      "wall clock then)" % (fired_ms, lag_ms))
# lateness is counted against the logical time at which pd handled the packet,
# i.e. (in this test's own mapping) the fire time minus (timetag - latency); the
# count is the running total, the strikes handled late above included. The
# expectation goes through the mapping (wall_of_logical), which is late by the
# tick reports' transit, in [0, rtt]: so the report may fall short of it by
# that much more than 1 ms, as the late strikes above are judged (a run under
# ASan on a slow core fell short by 1.02 ms with rtt 0.24 ms).
expected_late_ms = (late_fire - t_late) * 1000.0 + LATENCY_MS
last = lates[-1] if lates else None
# Before it, one report per late strike; any other is a strike pd handled late by less
# than the 1 ms it is judged by (on a loaded machine: 0.19 ms), so on time above.
slight = len(lates) - 1 - len(late_strikes)
slight_ok = slight >= 0 and all(
    r[2] <= 1.0 + rtt_ms for r in sorted(lates[:-1], key=lambda r: r[2])[:slight])
check(last is not None and slight_ok
      and -1.0 - rtt_ms <= last[2] - expected_late_ms <= 1.0 and last[3] == len(lates),
      "the late bundle's report, %.2f ms late (expected %.2f, from 1 ms + the mapping's %.3f "
      "below to 1 ms above), counted %s: %s"
      % (last[2] if last else -1, expected_late_ms, rtt_ms, last[3] if last else -1, lates))

poses = [a[1:] for _, a in records if a[0] == "pose"]
check(["frame", 42.0, 1.5] in poses and ["body", 3.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0]
      in poses, "pose frame and body pass through: %s" % poses)
replies = [a[1:] for _, a in records if a[0] == "reply"]
check(["reply", "tempo", "ok"] in replies and ["error", "grip", "unknown grip"] in replies
      and ["pong"] in replies, "reply, error and pong pass through: %s" % replies)


def decode(packet):
    """address, type tags, args of an OSC message (f, i, s only)."""
    end = packet.index(b"\0")
    addr = packet[:end].decode()
    pos = (end + 4) & ~3
    tend = packet.index(b"\0", pos)
    tags = packet[pos + 1:tend].decode()
    pos = (tend + 4) & ~3
    out = []
    for t in tags:
        if t == "f":
            out.append(struct.unpack(">f", packet[pos:pos + 4])[0])
            pos += 4
        elif t == "i":
            out.append(struct.unpack(">i", packet[pos:pos + 4])[0])
            pos += 4
        elif t == "s":
            e = packet.index(b"\0", pos)
            out.append(packet[pos:e].decode())
            pos = (e + 4) & ~3
    return addr, tags, out


got = [decode(p) for p in control]
check(("/ictus/tempo", "f", [96.0]) in got and ("/ictus/grip", "s", ["french"]) in got
      and ("/ictus/ping", "", []) in got, "control messages sent as OSC: %s" % got)
