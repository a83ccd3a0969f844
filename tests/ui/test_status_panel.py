"""[ictus-status] against the real daemon (docs/ui.md): pd in real time (not
batch: the panel polls on Pd's clock) with [ictus-receive] -> [ictus-status],
and `ictusd run` (score mode, --reply to Pd). The panel must show the daemon
answering and its state as /ictus/status gives it (source score, mode
cartesian, grip french: ictusd run's defaults for the built-in score), pass
on other replies (a tempo it sends) and errors (a tempo out of range: the
daemon's own refusal), not pass on the status replies it polls; when the daemon
is stopped it must say so within its 2.5 s watchdog. Waits are handshakes on
pd's printed lines, with deadlines."""
import argparse
import os
import signal
import socket
import subprocess
import tempfile

from ictus_tools import oscpacket, uitest
from ictus_tools.checks import check

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
ap.add_argument("--ictusd", required=True)
args = ap.parse_args()
build = os.path.abspath(args.build)


pd_port, daemon_port = uitest.free_udp_port(), uitest.free_udp_port()
pd_lines = uitest.PdLines()
printed = pd_lines.printed
wait_for = pd_lines.wait_for


with tempfile.TemporaryDirectory(prefix="ictus-ui-status-") as work:
    patch = os.path.join(work, "status.pd")
    with open(patch, "w") as f:
        f.write("#N canvas 0 0 600 400 12;\n"
                "#X obj 10 10 ictus-receive %d;\n"
                "#X obj 10 200 ictus-status;\n"
                "#X obj 10 260 print poll;\n#X obj 150 260 print other;\n#X obj 290 260 print panel;\n"
                "#X obj 300 10 loadbang;\n#X msg 300 40 connect 127.0.0.1 %d;\n"
                "#X connect 0 2 1 0;\n#X connect 1 0 0 0;\n#X connect 1 0 2 0;\n"
                "#X connect 1 1 3 0;\n#X connect 1 2 4 0;\n#X connect 5 0 6 0;\n#X connect 6 0 0 0;\n"
                % (pd_port, daemon_port))
    pd = subprocess.Popen([uitest.PD, "-nogui", "-nosound", "-nomidi", "-stderr", "-path",
                           os.path.join(build, "ictus"), "-open", patch],
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                          env=uitest.PD_ENV)
    pd_lines.follow(pd.stdout)
    env = dict(os.environ)
    env.pop("LD_PRELOAD", None)
    daemon = None
    try:
        wait_for(lambda l: l == "panel: answering 0", "NOT ANSWERING before the daemon starts", 30)
        daemon = subprocess.Popen([args.ictusd, "run", "--port", str(daemon_port),
                                   "--target", "osc.udp://127.0.0.1:%d" % pd_port,
                                   "--reply", "osc.udp://127.0.0.1:%d" % pd_port, "--pose-rate", "0"],
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
        wait_for(lambda l: l == "panel: answering 1", "answering once the daemon runs", 60)
        state = wait_for(lambda l: l.startswith("panel: state "), "a state line", 30).split()
        check(state[2:5] == ["score", "cartesian", "french"],
              "the panel shows the daemon's source, mode and grip: %s" % state[2:])
        check(float(state[6]) > 0, "... and its tempo (%s bpm)" % state[6])
        # ictusd replies to --reply (Pd's port) whoever sends: the test sends as Pd would.
        ctl = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        ctl.sendto(oscpacket.message("/ictus/tempo", "f", 1000.0), ("127.0.0.1", daemon_port))
        err = wait_for(lambda l: l.startswith("other: error"), "the daemon's refusal passed on", 30)
        check("/ictus/tempo" in err and "1000" in err, "the error names the address and value: %s" % err)
        ctl.sendto(oscpacket.message("/ictus/ping", ""), ("127.0.0.1", daemon_port))
        wait_for(lambda l: l.startswith("other: pong"), "pong passed on", 30)
        daemon.send_signal(signal.SIGTERM)
        daemon.wait(30)
        wait_for(lambda l: l == "panel: answering 0", "NOT ANSWERING after the daemon stopped", 30)
    finally:
        if daemon is not None and daemon.poll() is None:
            daemon.kill()
            daemon.wait()
        uitest.stop(pd)
check(sum(l == "poll: poll" for l in printed) >= 2, "the panel polls (poll: /ictus/status through ictus-receive)")
check(not [l for l in printed if "/ictus/status" in l and l.startswith("other:")],
      "status replies stay in the panel")
check(not uitest.error_lines("\n".join(l for l in printed if not l.startswith("other: error"))),
      "no error lines from pd")
print("PASS")
