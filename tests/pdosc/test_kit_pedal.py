"""A hi-hat's pedal live (docs/osc.md, /ictus/kit/pedal; docs/pd-osc.md, "[ictus-kit]"), in the
real pd in real time: bundles as ictusd sends them, /ictus/kit/pedal first and the /ictus/strike
it goes before, one timetag. [ictus-receive] must hold the pedal to the timetag like the strike,
and [ictus-kit test-kit] give it to the drum (test-kit-6 openness X): each pedal reaches the drum at
its strike's logical time, before the strike, with its openness; a strike without a pedal
brings none.

    PYTHONPATH=python python3 tests/pdosc/test_kit_pedal.py --build build
"""
import argparse
import os
import socket
import time

from ictus_tools.checks import check
from ictus_tools.oscpacket import bundle, message, now, strike, timetag
from ictus_tools.pdrun import Patch, error_lines
from ictus_tools.rtpd import Listener, free_udp_port, start_pd, wait_for_ticks

SECONDS = 600.0  # pd's own deadline: the test kills pd when done
HIHAT = 6
# (seq, delay after the first send in s, the pedal sent first in the bundle or None)
BUNDLES = [(1, 0.4, 0.0), (2, 0.7, None), (3, 1.0, 1.0), (4, 1.3, 0.5)]


def build(build_dir, pd_port, report_port):
    """[ictus-receive] -> [route kit] -> [ictus-kit test-kit]'s kit inlet; the strikes and what
    test-kit-6 receives reported with their logical time (ms since load)."""
    p = Patch(declare="-path %s/ictus" % build_dir)
    recv = p.obj("ictus-receive %d" % pd_port)
    rk = p.obj("route kit")
    kit = p.obj("ictus-kit test-kit")
    p.connect(recv, 2, rk, 0)
    p.connect(rk, 0, kit, 1)
    drum = p.obj("r test-kit-%d" % HIHAT)
    lb = p.obj("loadbang")
    t = p.obj("t b b b")
    p.connect(lb, 0, t, 0)
    net = p.obj("netsend -u")
    conn = p.msg("connect localhost %d" % report_port)
    p.connect(t, 2, conn, 0)
    p.connect(conn, 0, net, 0)

    def stamped(src, outlet, prefix):
        tba, app, tim = p.obj("t b a"), p.obj("list append"), p.obj("timer")
        lp, ls, lt = p.obj("list prepend %s" % prefix), p.obj("list prepend send"), p.obj("list trim")
        p.connect(t, 1, tim, 0)
        p.connect(src, outlet, tba, 0)
        p.connect(tba, 1, app, 1)
        p.connect(tba, 0, tim, 1)
        p.connect(tim, 0, app, 0)
        for a, b in ((app, lp), (lp, ls), (ls, lt), (lt, net)):
            p.connect(a, 0, b, 0)
        return tim

    stamped(recv, 0, "fire")
    stamped(drum, 0, "drum")
    metro = p.obj("metro 2")
    p.connect(t, 0, metro, 0)
    stamped(metro, 0, "tick")
    end = p.obj("delay %d" % int(SECONDS * 1000))
    q = p.msg("\\; pd quit")
    p.connect(t, 0, end, 0)
    p.connect(end, 0, q, 0)
    return p.text()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    build_dir = os.path.abspath(ap.parse_args().build)
    reports = Listener()
    pd_port = free_udp_port()
    proc, _ = start_pd(build(build_dir, pd_port, reports.port), build_dir)
    out = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        check(wait_for_ticks(reports), "pd runs in real time and reports ticks")
        t0 = now()
        for seq, delay, pedal in BUNDLES:
            parts = [] if pedal is None else [message("/ictus/kit/pedal", "if", HIHAT, pedal)]
            parts.append(strike(seq, 0, time_s=delay))
            out.sendto(bundle(timetag(t0 + delay), *parts), ("127.0.0.1", pd_port))
        deadline = time.time() + 10.0
        while time.time() < deadline:
            records = [a for _, a in reports.records() if a[0] != "tick"]
            if sum(a[0] == "fire" for a in records) >= len(BUNDLES):
                break
            time.sleep(0.02)
        time.sleep(0.1)  # a pedal reported after its strike would come in now
        records = [a for _, a in reports.records() if a[0] != "tick"]
    finally:
        out.close()
        proc.kill()
        log, _ = proc.communicate()
        reports.close()
    reports.require_intact()
    check(not error_lines(log), "pd ran cleanly: %s" % error_lines(log))
    # The reports in pd's order: each pedal, then the strike it goes before, at one logical
    # time (a strike list: hand, velocity, r/a, theta, mass, force, bounce, drum, seq ...).
    seen = [(a[0], a[1], a[2:]) for a in records]
    print("pd: %s" % seen)
    want = []
    for seq, _, pedal in BUNDLES:
        if pedal is not None:
            want.append(("drum", ["openness", pedal]))
        want.append(("fire", seq))
    got = [(k, rest[:2]) if k == "drum" else (k, int(rest[8])) for k, _, rest in seen]
    check(got == want, "pedal and strike in order: %s, want %s" % (got, want))
    for i, (kind, ms, _) in enumerate(seen):
        if kind == "drum":
            check(seen[i + 1][0] == "fire" and seen[i + 1][1] == ms,
                  "the pedal at its strike's logical time: %s ms and %s" % (ms, seen[i + 1][:2]))
    print("ok")


if __name__ == "__main__":
    main()
