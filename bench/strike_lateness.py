#!/usr/bin/env python3
"""How early strike bundles arrive before their timetag, live.

Runs `ictusd run` (score mode, the built-in score, replayed whenever it ends)
for SECONDS with its strikes sent here, and measures for every /ictus/strike
bundle the margin = timetag - arrival (wall clock, NTP; arrival is the kernel's
receive timestamp, so a busy receiver does not count as a late sender). A negative margin is a
late bundle: the sound would play it late. Optionally keeps the machine busy
with stress-ng beside it (--load). Prints the distribution; docs/benchmarks.md
("Strike lateness") keeps the figures.

usage: bench/strike_lateness.py ICTUSD [--seconds 600] [--lookahead 0.02] [--load] [--realtime]
"""
import argparse
import socket
import struct
import subprocess
import sys
import time

NTP_EPOCH = 2208988800  # seconds from 1900 to 1970
SO_TIMESTAMPNS = getattr(socket, "SO_TIMESTAMPNS", 35)  # Linux


def ntp_now():
    return time.time() + NTP_EPOCH


def osc_string(data, offset):
    end = data.index(b"\0", offset)
    return data[offset:end].decode(), (end + 4) & ~3


def bundle_messages(data):
    """(timetag seconds, [(address, payload)]) of a bundle, or None."""
    if not data.startswith(b"#bundle\0") or len(data) < 16:
        return None
    sec, frac = struct.unpack(">II", data[8:16])
    tt = sec + frac / 2**32
    out, i = [], 16
    while i + 4 <= len(data):
        (size,) = struct.unpack(">i", data[i : i + 4])
        element = data[i + 4 : i + 4 + size]
        address, _ = osc_string(element, 0)
        out.append((address, element))
        i += 4 + size
    return tt, out


def osc_message(address, types="", *args):
    def pad(b):
        return b + b"\0" * (4 - len(b) % 4)

    body = pad(address.encode()) + pad(("," + types).encode())
    for t, a in zip(types, args):
        body += struct.pack(">f", a) if t == "f" else pad(a.encode())
    return body


def percentile(sorted_values, q):
    if not sorted_values:
        return float("nan")
    k = min(len(sorted_values) - 1, max(0, int(round(q * (len(sorted_values) - 1)))))
    return sorted_values[k]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("ictusd")
    ap.add_argument("--seconds", type=float, default=600.0)
    ap.add_argument("--lookahead", type=float, default=None, help="default: ictusd's own")
    ap.add_argument("--load", action="store_true", help="stress-ng --cpu 0 beside it")
    ap.add_argument("--realtime", action="store_true", help="ictusd run --realtime")
    args = ap.parse_args()

    rx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    rx.bind(("127.0.0.1", 0))
    rx.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 20)
    rx.setsockopt(socket.SOL_SOCKET, SO_TIMESTAMPNS, 1)
    port = rx.getsockname()[1]
    probe = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    probe.bind(("127.0.0.1", 0))
    cmd_port = probe.getsockname()[1]
    probe.close()

    load = None
    if args.load:
        load = subprocess.Popen(["stress-ng", "--cpu", "0", "--quiet"])
    cmd = [args.ictusd, "run", "--autoplay", "--port", str(cmd_port), "--target",
           f"osc.udp://127.0.0.1:{port}", "--reply", f"osc.udp://127.0.0.1:{port}",
           "--pose-rate", "30"]
    if args.realtime:
        cmd.append("--realtime")
    if args.lookahead is not None:
        cmd += ["--lookahead", str(args.lookahead)]
    daemon = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    tx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    margins, ends = [], 0
    start = time.time()
    last_status = 0.0
    rx.settimeout(0.05)
    try:
        while time.time() - start < args.seconds:
            now = time.time()
            if now - last_status > 0.5:
                # Replay the score whenever it has ended (status: playing 0).
                tx.sendto(osc_message("/ictus/status"), ("127.0.0.1", cmd_port))
                last_status = now
            try:
                data, ancillary, _, _ = rx.recvmsg(65536, 256)
            except socket.timeout:
                continue
            # When the packet reached this host (the kernel's receive
            # timestamp), not when this script got round to reading it.
            arrival = ntp_now()
            for level, kind, cdata in ancillary:
                if level == socket.SOL_SOCKET and kind == SO_TIMESTAMPNS:
                    sec, nsec = struct.unpack("qq", cdata[:16])
                    arrival = sec + 1e-9 * nsec + NTP_EPOCH
            b = bundle_messages(data)
            if b:
                tt, messages = b
                for address, _ in messages:
                    if address == "/ictus/strike":
                        margins.append(tt - arrival)
                    elif address == "/ictus/strike/end":
                        ends += 1
                continue
            address, _ = osc_string(data, 0)
            if address == "/ictus/reply" and b"/ictus/status" in data:
                # ,sfifi...: address, time, playing
                off = data.index(b"/ictus/status")
                _, off = osc_string(data, off)
                playing = struct.unpack(">i", data[off + 4 : off + 8])[0]
                if playing == 0:
                    tx.sendto(osc_message("/ictus/play"), ("127.0.0.1", cmd_port))
    finally:
        daemon.terminate()
        daemon.wait()
        if load:
            load.terminate()
            load.wait()
    margins.sort()
    late = [m for m in margins if m < 0]
    ms = lambda v: f"{1e3 * v:.2f} ms"
    print(f"strike lateness: {args.seconds:.0f} s of ictusd run{' --realtime' if args.realtime else ''}, load={'stress-ng' if args.load else 'none'}, "
          f"lookahead {args.lookahead if args.lookahead is not None else 'default'}")
    print(f"  strikes received {len(margins)}, ends {ends}, late {len(late)}")
    if margins:
        print(f"  margin (timetag - arrival): min {ms(margins[0])}, p1 {ms(percentile(margins, 0.01))}, "
              f"median {ms(percentile(margins, 0.5))}, max {ms(margins[-1])}")
    return 0 if margins else 1


if __name__ == "__main__":
    sys.exit(main())
