#!/usr/bin/env python3
"""The ports the tests listen on (python/ictus_tools/pdrun.py free_port, and its C++ twin
in tests/support/osc_test_util.hpp): drawn by processes side by side, as ctest -j runs
them, none is drawn twice, each lies outside the kernel's ephemeral range (read here from
/proc, not from the helper) and can be bound by the process that drew it, for UDP and TCP;
a port another process holds a reservation on is never drawn, even when it could be bound."""
import os
import socket
import subprocess
import sys

from ictus_tools.checks import check, finish
from ictus_tools.pdrun import PORT_LOCK_DIR, free_port

PROCESSES = 6
PER_PROCESS = 40

CHILD = r"""
import socket, sys
from ictus_tools.pdrun import free_port
kind = socket.SOCK_STREAM if sys.argv[1] == "tcp" else socket.SOCK_DGRAM
ports = [free_port(kind) for _ in range(int(sys.argv[2]))]
print(" ".join(map(str, ports)), flush=True)
sys.stdin.read()   # holds its reservations until the parent has drawn its own
"""


def main():
    with open("/proc/sys/net/ipv4/ip_local_port_range") as f:
        low, high = (int(v) for v in f.read().split())
    kids = [subprocess.Popen([sys.executable, "-c", CHILD, "tcp" if k % 2 else "udp",
                              str(PER_PROCESS)], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                             text=True, env=dict(os.environ))
            for k in range(PROCESSES)]
    drawn = [[int(p) for p in kid.stdout.readline().split()] for kid in kids]
    # while the children hold theirs: this process draws, and each port it draws binds
    mine = []
    for _ in range(PER_PROCESS):
        port = free_port()
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
            s.bind(("127.0.0.1", port))
        mine.append(port)
    for kid in kids:
        kid.stdin.close()
        kid.wait(30)
    everyone = [p for ports in drawn for p in ports] + mine
    check(all(len(ports) == PER_PROCESS for ports in drawn),
          "each of %d processes drew %d ports" % (PROCESSES, PER_PROCESS))
    check(len(set(everyone)) == len(everyone), "%d ports drawn side by side, none twice"
          % len(everyone))
    outside = [p for p in everyone if not low <= p <= high]
    check(len(outside) == len(everyone), "all outside the ephemeral range %d..%d (inside: %s)"
          % (low, high, sorted(set(everyone) - set(outside))[:5]))
    check(all(1024 <= p <= 65535 for p in everyone), "all unprivileged ports")
    check(os.path.isdir(PORT_LOCK_DIR), "reservations in %s" % PORT_LOCK_DIR)
    finish()


if __name__ == "__main__":
    main()
