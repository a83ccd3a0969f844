"""[ictus-receive]'s schedule and its socket, in the real pd in real time (docs/pd-osc.md,
"The schedule"): 10 strikes due within 1 s, then 300 bundles time-tagged an hour ahead (as a
stray sender could post them): each of the 10 fires with its own data, none of the 300 fires.
Then enough more far-future bundles to pass the schedule's 4096 pending strikes: the excess is
refused and counted, and `status` reports the count, which must equal the strike packets pd
received (its own packet counter, [ictus_timetag]'s status) minus the 10 fired minus 4096.
The socket: the abstraction listens on 127.0.0.1 by default and on every interface when its
second argument says 0.0.0.0, read from the kernel's table (/proc/net/udp), not from Pd.

    PYTHONPATH=python python3 tests/pdosc/test_schedule.py --build build
"""
import argparse
import os
import socket
import time

from ictus_tools.checks import check
from ictus_tools.oscpacket import bundle, now, strike, timetag
from ictus_tools.pdrun import error_lines
from ictus_tools.rtpd import (Listener, build_patch, free_udp_port, start_pd,
                              wait_for_ticks, wait_records)

CAPACITY = 4096  # the schedule's pending strikes (patches/ictus-receive.pd)
# OVER: far more than needed, so that the capacity is passed even when a loaded machine
# drops datagrams on the way (the check counts what reached pd, not what was sent); and
# sent again while pd reports fewer than the capacity
REAL, JUNK, OVER = 10, 300, 600
SECONDS = 600.0  # pd's own deadline: the test kills pd when done


def bound_address(port):
    """The local address (hex, as the kernel prints it) of the UDP socket bound to port."""
    with open("/proc/net/udp") as f:
        rows = [line.split() for line in f.readlines()[1:]]
    return [r[1].split(":")[0] for r in rows if int(r[1].split(":")[1], 16) == port]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    build = os.path.abspath(ap.parse_args().build)
    reports = Listener()
    pd_port, fudi_port, any_port = free_udp_port(), free_udp_port(), free_udp_port()
    patch = build_patch(build, pd_port, reports.port, SECONDS, fudi_in_port=fudi_port)
    patch += "#X obj 600 10 ictus-receive %d 0.0.0.0;\n" % any_port
    proc, work = start_pd(patch, build)
    out = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sent = {}
    try:
        check(wait_for_ticks(reports), "pd runs in real time and reports ticks")
        check(bound_address(pd_port) == ["0100007F"], "ictus-receive PORT listens on 127.0.0.1 "
              "only: %s" % bound_address(pd_port))
        check(bound_address(any_port) == ["00000000"], "ictus-receive PORT 0.0.0.0 listens on "
              "every interface: %s" % bound_address(any_port))
        t0 = now() + 0.3
        for k in range(REAL):
            seq = k + 1
            tag = t0 + 0.06 * k
            vel, ra, th = 0.5 + 0.25 * seq, 0.02 * seq, 11.0 * seq
            out.sendto(bundle(timetag(tag), strike(seq, seq % 2, vel, ra, th)),
                       ("127.0.0.1", pd_port))
            sent[seq] = (seq % 2, vel, ra, th)
        for k in range(JUNK):
            out.sendto(bundle(timetag(now() + 3600.0), strike(10000 + k, 1, 9.5, 0.9, 333.0)),
                       ("127.0.0.1", pd_port))
        records = wait_records(reports, lambda r: sum(a[0] == "fire" for _, a in r) >= REAL,
                               "the %d real strikes fired" % REAL)
        reports.require_intact()
        fires = {int(a[10]): a[2:] for _, a in records if a[0] == "fire"}
        check(sorted(fires) == sorted(sent), "exactly the real strikes fired: %s" % sorted(fires))
        for seq, (hand, vel, ra, th) in sorted(sent.items()):
            f = fires[seq]
            check(f[0] == hand and abs(f[1] - vel) < 1e-4 and abs(f[2] - ra) < 1e-5
                  and abs(f[3] - th) < 1e-3, "strike %d fired with its own data: %s" % (seq, f))
        asked = [0]

        def status_packets():
            """The strike packets pd has taken so far, by asking it (a handshake)."""
            out.sendto(b"status;\n", ("127.0.0.1", fudi_port))
            asked[0] += 1
            got = wait_records(reports, lambda r: sum(a[:2] == ["info", "status"]
                                                      for _, a in r) >= asked[0],
                               "status answer %d" % asked[0])
            return got, int([a for _, a in got if a[:2] == ["info", "status"]][-1][5])

        # past the capacity: paced so that pd's socket buffer keeps up, and sent again in
        # batches of OVER until pd reports more packets than the schedule holds (a loaded
        # machine drops datagrams on the way), with a deadline
        k, batch, t_end = 0, CAPACITY - JUNK + OVER, time.time() + 60.0
        while True:
            for _ in range(batch):
                out.sendto(bundle(timetag(now() + 3600.0), strike(20000 + k, 0)),
                           ("127.0.0.1", pd_port))
                k += 1
                if k % 25 == 0:
                    time.sleep(0.01)
            batch = OVER
            _, packets = status_packets()
            if packets > REAL + CAPACITY or time.time() > t_end:
                break
        # Handshake: ask for the status until two answers running report the same packet
        # count (every packet that reached pd has been through the schedule), with a deadline.
        last, t_end = None, time.time() + 30.0
        while time.time() < t_end:
            records, packets = status_packets()
            if packets == last:
                break
            last = packets
        records = wait_records(reports, lambda r: any(a[:2] == ["info", "refused"] for _, a in r),
                               "the refused report")
    finally:
        out.close()
        proc.kill()
        log, _ = proc.communicate()
        reports.close()
    check(not error_lines(log.replace("error: ictus-receive: the schedule holds", "")),
          "pd ran cleanly: %s" % error_lines(log))
    status = [a for _, a in records if a[:2] == ["info", "status"]][-1]
    refused = [a for _, a in records if a[:2] == ["info", "refused"]][-1]
    packets = int(status[5])
    expected = packets - REAL - CAPACITY
    print("pd received %d strike packets; refused %s" % (packets, refused[2:]))
    check(expected > 0, "enough packets reached pd to pass the capacity (%d)" % packets)
    check(refused[2:] == [expected, CAPACITY], "refused %d of capacity %d, reported %s"
          % (expected, CAPACITY, refused[2:]))
    check(sum(1 for line in log.splitlines() if "the schedule holds" in line) == 1,
          "the refusal printed once, then only counted")
    print("ok")


if __name__ == "__main__":
    main()
