"""The main patch against the real daemon (docs/ui.md, "The panels against the
daemon"): a copy of <build>/patches/ictus.pd, listening on a free port and
sending to a real `ictusd run`, in the real pd (-nogui, in real time: the
daemon panel polls /ictus/status on Pd's clock and its watchdog is 2.5 s of
it, which -batch would run faster than the wall clock). The test moves every
control of the physics panel (through the receive names the controls take,
ictus-physics-*), clicks the score boxes (a [r] added to each), and checks
each control's effect: the daemon's reply or error, printed by the patch, and
its state as /ictus/status reports it and the panel shows it (the panel's
second outlet, printed). Score mode (the built-in score), then clip mode
(--mocap, when the CMU clip is there): there the panel covers nuance, control
mode and clear score, and what they would send never reaches the daemon (a
ping sent after them is answered with nothing before its pong). Every wait is
a handshake on pd's printed lines, with a deadline."""
import argparse
import math
import os
import re
import signal
import socket
import subprocess
import tempfile

from ictus_tools import uitest
from ictus_tools.checks import check

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
ap.add_argument("--ictusd", required=True)
ap.add_argument("--clip", default="")
args = ap.parse_args()
build = os.path.abspath(args.build)


pd_port, daemon_port, ctl_port = uitest.free_udp_port(), uitest.free_udp_port(), uitest.free_udp_port()
pd_lines = uitest.PdLines()
printed = pd_lines.printed
wait_for = pd_lines.wait_for


def unescape(line):
    return line.replace("\\ ", " ")


def state_where(pred, what, timeout=60):
    """The next status the daemon panel received that satisfies pred(fields):
    source, mode, grip, playing, tempo, strikes."""
    def match(line):
        if not line.startswith("state: state "):
            return False
        f = line.split()[2:]
        return pred(dict(source=f[0], mode=f[1], grip=f[2], playing=int(float(f[3])),
                         tempo=float(f[4]), strikes=int(float(f[5]))))
    f = wait_for(match, what, timeout).split()[2:]
    return dict(source=f[0], mode=f[1], grip=f[2], playing=int(float(f[3])), tempo=float(f[4]),
                strikes=int(float(f[5])))


ctl = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)


def move(name, value=0):
    """Sets a panel control as a hand would (its receive name), or clicks a box."""
    ctl.sendto(("%s %s;\n" % (name, value)).encode(), ("127.0.0.1", ctl_port))


def reply(address, *words):
    want = " ".join(("ictusd: reply", address) + tuple(str(w) for w in words))
    wait_for(lambda l: unescape(l) == want, "'%s'" % want)


def shown(text, timeout=60):
    wait_for(lambda l: unescape(l) == "shown: " + text, "the panel shows '%s'" % text, timeout)


def nothing_sent_before_pong(what):
    """Pings through the panel: the daemon answers in order, so what a disabled
    control would have sent would be answered before the pong."""
    move("ictus-physics-ping")
    seen = []
    wait_for(lambda l: seen.append(l) or l == "ictusd: pong", "pong after %s" % what)
    sent = [l for l in seen if l.startswith("ictusd: reply") or l.startswith("ictusd: error")]
    check(not sent, "%s: nothing reached the daemon (before the pong: %s)" % (what, sent))


def drum_controls(radius, tension, mass):
    """The sound panel's membrane controls (its inlet sets them as a hand would)
    reach the daemon as the drum: radius, tension, and the density mass / (pi a^2)."""
    move("test-sound", "radius %g" % radius)
    reply("/ictus/drum/radius", "%g" % radius)
    move("test-sound", "tension %g" % tension)
    reply("/ictus/drum/tension", "%g" % tension)
    move("test-sound", "mass %g" % mass)
    line = wait_for(lambda l: l.startswith("ictusd: reply /ictus/drum/density "), "the density")
    density = float(line.split()[-1])
    want = mass / (math.pi * radius * radius)
    check(abs(density - want) <= 1e-5 * want, "drum density %g = mass / (pi a^2) = %g" % (density, want))


def start_daemon(extra, log):
    env = dict(os.environ)
    env.pop("LD_PRELOAD", None)  # pd's ASan preload is not the daemon's
    return subprocess.Popen([args.ictusd, "run", "--port", str(daemon_port),
                             "--target", "osc.udp://127.0.0.1:%d" % pd_port,
                             "--reply", "osc.udp://127.0.0.1:%d" % pd_port, "--pose-rate", "0"]
                            + extra, stdout=log, stderr=subprocess.STDOUT, env=env)


def stop_daemon(daemon):
    daemon.send_signal(signal.SIGTERM)
    try:
        daemon.wait(30)
    except subprocess.TimeoutExpired:
        daemon.kill()
        daemon.wait()


# The main patch as built, listening on pd_port, sending to daemon_port, with a
# remote hand (FUDI on ctl_port: '<receive name> <value>;' to that name), and
# prints of what the physics panel shows and of the daemon panel's state.
main = open(os.path.join(build, "patches", "ictus.pd")).read()
check("ictus-receive 9000;" in main and "connect 127.0.0.1 9001;" in main,
      "the main patch listens on 9000 and sends to 9001")
main = main.replace("ictus-receive 9000;", "ictus-receive %d;" % pd_port)
main = main.replace("connect 127.0.0.1 9001;", "connect 127.0.0.1 %d;" % daemon_port)
records = [r for r in re.split(r"(?<!\\);\n", main) if r.strip()]
boxes = uitest.top_level_boxes(records)
index = {}
for n, kind, words in boxes:
    if kind == "obj" and words[4] in ("ictus-physics", "ictus-status", "ictus-sound-panel"):
        index[words[4]] = n
    if kind == "msg":
        index.setdefault("boxes", []).append((n, re.sub(r", f \d+$", "", " ".join(words[4:]))))
check("ictus-physics" in index and "ictus-status" in index and "ictus-sound-panel" in index
      and len(index["boxes"]) >= 4,
      "the main patch has the physics and daemon panels and score boxes")
score_boxes = [(i, t) for i, t in index["boxes"] if "R" in t.split()]
replace_boxes = [(i, t) for i, t in score_boxes if t.startswith("clear") and "play" in t]
append_boxes = [(i, t) for i, t in score_boxes if not t.startswith("clear")]
check(len(replace_boxes) >= 3 and len(append_boxes) >= 1,
      "score boxes that replace and play (%d) and one that appends (%d)"
      % (len(replace_boxes), len(append_boxes)))
extra = ["#X obj 20 1000 netreceive -u %d" % ctl_port, "#X obj 20 1030 list",
         "#X obj 20 1060 t a a", "#X obj 200 1090 list split 1", "#X obj 200 1120 symbol",
         "#X obj 20 1090 list split 1", "#X obj 20 1150 s", "#X obj 400 1000 print shown",
         "#X obj 600 1000 print state", "#X obj 20 1120 list trim"]
conns = [(0, 0, 1, 0), (1, 0, 2, 0), (2, 1, 3, 0), (3, 0, 4, 0), (4, 0, 6, 1), (2, 0, 5, 0),
         (5, 1, 9, 0), (9, 0, 6, 0)]
base = len(boxes)
for k, (i, _) in enumerate(score_boxes):
    extra.append("#X obj %d 1200 r test-box-%d" % (20 + 120 * k, i))  # base + 10 + k
extra.append("#X obj 20 1250 r test-sound")
links = [(base + a, o, base + b, i) for a, o, b, i in conns]
links += [(index["ictus-physics"], 1, base + 7, 0), (index["ictus-status"], 2, base + 8, 0)]
links += [(base + 10 + k, 0, i, 0) for k, (i, _) in enumerate(score_boxes)]
links += [(base + 10 + len(score_boxes), 0, index["ictus-sound-panel"], 0)]
text = ";\n".join(records) + ";\n" + "".join(e + ";\n" for e in extra)
text += "".join("#X connect %d %d %d %d;\n" % l for l in links)

with tempfile.TemporaryDirectory(prefix="ictus-ui-panels-") as work:
    patch = os.path.join(work, "ictus.pd")
    open(patch, "w").write(text)
    log = open(os.path.join(work, "ictusd.log"), "w")
    pd = subprocess.Popen([uitest.PD, "-nogui", "-nosound", "-nomidi", "-stderr", "-path",
                           os.path.join(build, "ictus"), "-open", patch],
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                          env=uitest.PD_ENV)
    pd_lines.follow(pd.stdout)
    daemon = None
    try:
        # ---- nobody there: the panel says so
        shown("daemon NOT ANSWERING")
        # ---- score mode: the built-in score, waiting for play
        daemon = start_daemon([], log)
        shown("source score")
        s = state_where(lambda s: True, "a status")
        check(s["source"] == "score" and s["mode"] == "cartesian" and s["grip"] == "french",
              "the daemon plays scores, Cartesian, French grip: %s" % s)
        shown("daemon score stopped")
        # The built-in score begins at 90 bpm (docs/score.md): the tempo box follows.
        shown("tempo 90")
        for _ in range(3):
            s = state_where(lambda s: True, "a status while waiting for play")
            check(s["playing"] == 0 and s["strikes"] == 0,
                  "ictusd run waits for play: not playing, no strike (%s)" % s)

        # tempo, stopped: the next play starts there
        move("ictus-physics-tempo", 120)
        reply("/ictus/tempo", 120)
        state_where(lambda s: s["tempo"] == 120, "the daemon's tempo 120 (stopped)")
        # grip, control mode: at once, both ways
        move("ictus-physics-grip", 1)
        reply("/ictus/grip", "german")
        shown("grip german")
        move("ictus-physics-grip", 0)
        reply("/ictus/grip", "french")
        shown("grip french")
        move("ictus-physics-mode", 0)
        reply("/ictus/mode", "joint")
        shown("mode joint")
        move("ictus-physics-mode", 1)
        reply("/ictus/mode", "cartesian")
        shown("mode cartesian")
        # gains: both scales, accepted
        move("ictus-physics-ks", 1.5)
        reply("/ictus/gains", 1.5, 1)
        move("ictus-physics-kd", 1.25)
        reply("/ictus/gains", 1.5, 1.25)
        move("ictus-physics-ks", 1)
        reply("/ictus/gains", 1, 1.25)
        move("ictus-physics-kd", 1)
        reply("/ictus/gains", 1, 1)
        move("ictus-physics-ping")
        wait_for(lambda l: l == "ictusd: pong", "pong")
        move("ictus-physics-nuance", 2)
        reply("/ictus/nuance", "accent")
        move("ictus-physics-nuance", 0)
        reply("/ictus/nuance", "legato")
        move("ictus-physics-clear")
        reply("/ictus/score/clear")
        drum_controls(0.2, 3500, 0.03)
        drum_controls(0.178, 3000, 0.0261)

        # a score box: clear, its statements, play -- one click
        ramp = [b for b in replace_boxes if "->" in b[1]][0]
        move("test-box-%d" % ramp[0])
        reply("/ictus/score/clear")
        for statement in [w.strip() for w in ramp[1].split("\\,")][1:-1]:
            reply("/ictus/score", statement)
        reply("/ictus/play")
        s = state_where(lambda s: s["playing"] == 1, "the box's score playing")
        shown("daemon score playing")
        # tempo while it plays: the score's map scaled from its next strokes on;
        # the score alone never goes past 140 bpm (its ramp's end)
        move("ictus-physics-tempo", 200)
        reply("/ictus/tempo", 200)
        state_where(lambda s: s["playing"] == 1 and s["tempo"] >= 199,
                    "the daemon playing at 200 bpm and more")
        s = state_where(lambda s: s["strikes"] > 0, "strikes")
        move("ictus-physics-stop")
        reply("/ictus/stop")
        shown("daemon score stopped")

        # a tempo the score cannot take: the daemon's error, shown in the panel
        move("test-box-%d" % ramp[0])
        reply("/ictus/play")
        state_where(lambda s: s["playing"] == 1, "playing again")
        move("ictus-physics-tempo", 400)
        err = wait_for(lambda l: l.startswith("ictusd: error /ictus/tempo"), "the refusal of 400 bpm")
        check("400" in err, "the error names the range: %s" % unescape(err))
        # (the panel may have shown it before the patch printed it)
        shown_error = lambda l: unescape(l).startswith("shown: reply error /ictus/tempo tempo:")
        if not any(shown_error(l) for l in printed[-20:]):
            wait_for(shown_error, "the refusal shown in the panel")
        check(True, "the refusal is shown in the physics panel's last reply")
        move("ictus-physics-stop")
        reply("/ictus/stop")

        # the append box: its statements join those received; nothing plays
        # until play, which plays them all
        app = append_boxes[0]
        move("test-box-%d" % app[0])
        for statement in [w.strip() for w in app[1].split("\\,")]:
            reply("/ictus/score", statement)
        s = state_where(lambda s: True, "a status after the append box")
        check(s["playing"] == 0, "appending does not play")
        move("ictus-physics-play")
        reply("/ictus/play")
        state_where(lambda s: s["playing"] == 1, "play plays the statements received")
        move("ictus-physics-stop")
        reply("/ictus/stop")

        stop_daemon(daemon)
        daemon = None
        shown("daemon NOT ANSWERING")

        # ---- clip mode
        if not (args.clip and os.path.exists(args.clip)):
            print("SKIP (clip part): no CMU clip at '%s'" % args.clip)
        else:
            daemon = start_daemon(["--mocap", args.clip], log)
            shown("source clip", 120)
            s = state_where(lambda s: True, "a clip status")
            check(s["source"] == "clip" and s["mode"] == "joint" and s["playing"] == 0,
                  "the clip waits for play, in joint space: %s" % s)
            shown("daemon clip stopped")
            # covered: nuance, control mode, clear score, score statements
            move("ictus-physics-nuance", 3)
            shown("reply nuance: a clip has no nuances (score mode only)")
            move("ictus-physics-mode", 1)
            shown("reply mode: a clip plays in joint space only (eq. 1)")
            move("ictus-physics-clear")
            shown("reply score/clear: the daemon plays a clip (no score)")
            move("test-box-%d" % replace_boxes[0][0])
            wait_for(lambda l: unescape(l).startswith("shown: reply score statements:"),
                     "the score box refused in the panel")
            nothing_sent_before_pong("nuance, mode, clear score and a score box in clip mode")
            # what a clip can do
            move("ictus-physics-tempo", 150)
            reply("/ictus/tempo", 150)
            state_where(lambda s: s["tempo"] == 150, "the clip's tempo 150")
            move("ictus-physics-grip", 1)
            reply("/ictus/grip", "german")
            shown("grip german")
            move("ictus-physics-ks", 1.5)
            reply("/ictus/gains", 1.5, 1)
            move("ictus-physics-ks", 1)
            reply("/ictus/gains", 1, 1)
            drum_controls(0.2, 3500, 0.03)
            move("ictus-physics-ping")
            wait_for(lambda l: l == "ictusd: pong", "pong (clip)")
            move("ictus-physics-play")
            reply("/ictus/play")
            state_where(lambda s: s["playing"] == 1, "the clip playing", 120)
            move("ictus-physics-stop")
            reply("/ictus/stop")
            state_where(lambda s: s["playing"] == 0, "the clip stopped")
            stop_daemon(daemon)
            daemon = None
            shown("daemon NOT ANSWERING")
    finally:
        if daemon is not None and daemon.poll() is None:
            daemon.kill()
            daemon.wait()
        uitest.stop(pd)
        log.close()
bad = uitest.error_lines("\n".join(l for l in printed
                                   if not l.startswith("ictusd: error")
                                   and not l.startswith("shown: reply error")))
check(not bad, "no error lines from pd: %s" % bad)
print("PASS")
