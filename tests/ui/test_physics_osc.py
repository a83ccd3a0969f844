"""The physics panel's messages reach the daemon's port as the OSC of docs/osc.md:
[ictus-physics] -> [ictus-receive] (its control path, netsend) -> UDP -> this test,
which parses the packets itself. A score statement, whatever its words and
numbers, must arrive whole as one string (/ictus/score ,s "R accent 0.8 1/2"), in
order; a daemon reply fed back into the panel is shown without an error line."""
import argparse
import os
import socket
import struct
import subprocess
import tempfile

from ictus_tools import uitest
from ictus_tools.checks import check

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
build = os.path.abspath(args.build)

STATEMENTS = ["tempo 96 -> 140 over 8", "R accent 0.8 1/2", "L", "repeat 4", "grip german",
              "rest beats 2", "L accent ff at 0.3 0"]


def parse(packet):
    """address, type tags, arguments of a plain OSC message."""
    def string(pos):
        end = packet.index(b"\0", pos)
        return packet[pos:end].decode(), (end + 4) & ~3
    address, pos = string(0)
    tags, pos = string(pos)
    out = []
    for t in tags[1:]:
        if t == "s":
            s, pos = string(pos)
            out.append(s)
        elif t == "f":
            out.append(struct.unpack(">f", packet[pos:pos + 4])[0])
            pos += 4
        elif t == "i":
            out.append(struct.unpack(">i", packet[pos:pos + 4])[0])
            pos += 4
    return address, tags, out


sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
sock.bind(("127.0.0.1", 0))
sock.settimeout(10)
port = sock.getsockname()[1]
messages = " \\, ".join(STATEMENTS)
with tempfile.TemporaryDirectory(prefix="ictus-ui-osc-") as work:
    patch = os.path.join(work, "osc.pd")
    with open(patch, "w") as f:
        f.write("#N canvas 0 0 400 300 12;\n"
                "#X obj 10 10 loadbang;\n"
                "#X obj 10 40 t b b;\n"
                "#X msg 10 70 %s;\n"
                "#X obj 10 100 ictus-physics;\n"
                "#X obj 10 130 ictus-receive;\n"
                "#X msg 200 70 connect 127.0.0.1 %d;\n"
                "#X msg 300 100 reply /ictus/score R\\ accent;\n"
                "#X obj 200 160 delay 50;\n"
                "#X msg 200 190 \\; pd quit;\n"
                "#X connect 0 0 1 0;\n#X connect 1 1 5 0;\n#X connect 1 0 2 0;\n"
                "#X connect 2 0 3 0;\n#X connect 3 0 4 0;\n#X connect 5 0 4 0;\n"
                "#X connect 1 0 6 0;\n#X connect 6 0 3 1;\n#X connect 1 0 7 0;\n#X connect 7 0 8 0;\n"
                % (messages, port))
    proc = subprocess.run(uitest.PD_BATCH + ["-path", os.path.join(build, "ictus"), "-open", patch],
                          capture_output=True, text=True, timeout=60, env=uitest.PD_ENV)
log = proc.stdout + proc.stderr
check(proc.returncode == 0 and not uitest.error_lines(log), "pd ran without error lines" + ("" if not log else ": " + log))
got = []
sock.settimeout(2)
try:
    while len(got) < len(STATEMENTS):
        got.append(parse(sock.recv(4096)))
except socket.timeout:
    pass
check(len(got) == len(STATEMENTS), "one packet per statement (%d of %d)" % (len(got), len(STATEMENTS)))
for want, (address, tags, values) in zip(STATEMENTS, got):
    check(address == "/ictus/score" and tags == ",s" and values == [want],
          "%r -> /ictus/score ,s %r (got %s %s %r)" % (want, want, address, tags, values))
