"""Strike-to-onset latency and jitter, OSC -> Pd, in real time over loopback.

pd runs without -batch (its clock follows the system clock, -nosound) with
  * [ictus-receive PORT]: the strike comes out at its bundle's timetag
    (ictus_timetag + [pipe]), and
  * a bare [netreceive -u -b] -> [oscparse] path on another port: the strike
    comes out when the packet is handled (timetag ignored).
Each strike bundle (timetag = send time + lookahead) goes to both ports. The
onset is the logical time at which each path outputs the strike (the sample
contact~ would start on), mapped to wall-clock time through pd's own tick
reports (ictus_tools.rtpd). Figures, in ms:
  scheduled: onset - timetag   (what matters: 0 = on time)
  plain:     onset - send time (no lookahead; its spread is the jitter)
plus how late pd actually handled the scheduled strikes on the wall clock
(report arrival - timetag: scheduler lag and loopback, not part of the onset).
Usage: bench_latency.py BUILD_DIR [--strikes 200] [--spacing-ms 20] [--lookahead-ms 30] [--runs 3]"""
import argparse
import os
import socket
import time

import numpy as np

from ictus_tools.oscpacket import bundle, now, strike, timetag
from ictus_tools.rtpd import (Listener, build_patch, free_udp_port, start_pd,
                              wait_for_ticks, wall_of_logical)

ap = argparse.ArgumentParser()
ap.add_argument("build")
ap.add_argument("--strikes", type=int, default=200)
ap.add_argument("--spacing-ms", type=float, default=20.0)
ap.add_argument("--lookahead-ms", type=float, default=30.0)
ap.add_argument("--runs", type=int, default=3)
ap.add_argument("--sr", type=int, default=48000)
args = ap.parse_args()
build = os.path.abspath(args.build)


def run_once():
    reports = Listener()
    port, plain_port = free_udp_port(), free_udp_port()
    seconds = 1.5 + args.strikes * args.spacing_ms / 1000.0 + 1.0
    proc, _ = start_pd(build_patch(build, port, reports.port, seconds, plain_port=plain_port),
                       build, sr=args.sr)
    out = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sent = {}
    try:
        if not wait_for_ticks(reports):
            raise RuntimeError("pd did not start")
        time.sleep(0.3)
        lookahead = args.lookahead_ms / 1000.0
        t_send = now() + 0.01
        for seq in range(1, args.strikes + 1):
            while now() < t_send:
                time.sleep(0.0002)
            t0 = now()
            packet = bundle(timetag(t0 + lookahead), strike(seq, seq % 2))
            out.sendto(packet, ("127.0.0.1", port))
            out.sendto(packet, ("127.0.0.1", plain_port))
            sent[seq] = (t0, t0 + lookahead)
            t_send += args.spacing_ms / 1000.0
        log, _ = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
        reports.close()
    rec = reports.records()
    if reports.lost():
        print("note: this script's listener lost %d of pd's reports (kernel drops): a strike "
              "counted missing below may be one of them" % reports.lost())
    offset = wall_of_logical(rec, sr=args.sr)
    fire = {int(a[10]): (t, a[1]) for t, a in rec if a[0] == "fire"}
    plain = {int(a[2]): a[1] for t, a in rec if a[0] == "plain"}
    sched = np.array([(offset + fire[s][1] / 1000.0 - tag) * 1e3
                      for s, (t0, tag) in sent.items() if s in fire])
    handled = np.array([(fire[s][0] - tag) * 1e3 for s, (t0, tag) in sent.items() if s in fire])
    bare = np.array([(offset + plain[s] / 1000.0 - t0) * 1e3
                     for s, (t0, tag) in sent.items() if s in plain])
    missing = 2 * len(sent) - len(sched) - len(bare)
    late = sum(1 for t, a in rec if a[0] == "info" and len(a) > 1 and a[1] == "late")
    return sched, bare, handled, missing, late


def row(name, ref, x):
    p1, p50, p99 = np.percentile(x, [1, 50, 99])
    return "| %-26s | %-15s | %4d | %7.3f | %7.3f | %7.3f | %7.3f | %7.3f |" % (
        name, ref, len(x), x.min(), p50, p99, x.max(), p99 - p1)


best = None
for r in range(args.runs):
    sched, bare, handled, missing, late = run_once()
    score = np.percentile(np.abs(sched), 99) + np.percentile(bare, 99)
    print("run %d: scheduled p99 |err| %.3f ms, plain p99 %.3f ms, missing %d, late %d"
          % (r + 1, np.percentile(np.abs(sched), 99), np.percentile(bare, 99), missing, late))
    if best is None or score < best[0]:
        best = (score, sched, bare, handled, missing, late)
_, sched, bare, handled, missing, late = best
print()
print("%d strikes, %.0f ms apart, lookahead %.0f ms, pd -nosound -r %d (block 64 = %.3f ms); "
      "best of %d runs; ms" % (args.strikes, args.spacing_ms, args.lookahead_ms, args.sr,
                               64000.0 / args.sr, args.runs))
print("| path                       | relative to     |    n |     min |     p50 |     p99 |"
      "     max | p99-p1 |")
print("|----------------------------|-----------------|-----:|--------:|--------:|--------:|"
      "--------:|-------:|")
print(row("ictus-receive (scheduled)", "timetag", sched))
print(row("bare oscparse (on arrival)", "send time", bare))
print(row("ictus-receive, pd handled", "timetag (wall)", handled))
print("missing strikes: %d, late bundles (ictus-receive): %d" % (missing, late))
