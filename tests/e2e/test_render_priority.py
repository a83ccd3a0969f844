"""`ictusd render --wav` runs its batch pd without real-time priority (-nrt, docs/main-job.md).
Run as root, pd takes SCHED_FIFO unless told not to; a batch render never sleeps, so it would
hold a core against every ordinary process, and starve a live pd of the same priority, for as
long as it renders. Seen from outside, in /proc: the scheduling policy of the pd that ictusd
spawns, sampled while it renders, is SCHED_OTHER throughout. The same pd started here in batch
mode without -nrt takes SCHED_FIFO, so the check can fail on this machine. Skipped (exit 77)
when not root: pd cannot take SCHED_FIFO then, and there is nothing to tell apart.

    PYTHONPATH=python python3 tests/e2e/test_render_priority.py --build build --score SCORE
"""
import argparse
import os
import subprocess
import sys
import threading
import time

from ictus_tools import e2e_util as u
from ictus_tools.checks import check
from ictus_tools.pdrun import PD, make_workdir

SCHED_OTHER, SCHED_FIFO = 0, 1
DEADLINE_S = 60.0


def stat(pid):
    """(comm, ppid, policy) from /proc/PID/stat, or None when the process is gone."""
    try:
        with open("/proc/%d/stat" % pid) as f:
            text = f.read()
    except OSError:
        return None
    comm = text[text.index("(") + 1:text.rindex(")")]
    rest = text[text.rindex(")") + 2:].split()  # rest[0] is field 3 (state)
    return comm, int(rest[1]), int(rest[41 - 3])


def children_named(parent, name):
    """The pids of parent's children whose command is name."""
    found = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            s = stat(int(entry))
            if s and s[0] == name and s[1] == parent:
                found.append(int(entry))
    return found


def policies_while(proc, name):
    """The policies of proc's children called name, sampled every few ms until proc ends."""
    seen = []
    while proc.poll() is None:
        for pid in children_named(proc.pid, name):
            s = stat(pid)
            if s:
                seen.append(s[2])
        time.sleep(0.002)
    return seen


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    ap.add_argument("--score", required=True)
    args = ap.parse_args()
    if os.geteuid() != 0:
        print("SKIP: not root: pd cannot take SCHED_FIFO, so -nrt changes nothing to see")
        sys.exit(77)
    work = make_workdir("ictus-render-priority-")

    # The control: the same pd in batch mode without -nrt takes SCHED_FIFO here.
    patch = os.path.join(work, "idle.pd")
    with open(patch, "w") as f:
        f.write("#N canvas 0 0 200 200 12;\n")
    env = u.pd_spawning_env(work)
    shell = subprocess.Popen(["sh", "-c", 'exec "$0" -nogui -nosound -batch -stderr -open "$1"',
                              "pd", patch], env=env, stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL)
    policy, t0 = None, time.time()
    try:
        while time.time() - t0 < DEADLINE_S and shell.poll() is None:
            s = stat(shell.pid)
            if s and s[0] == "pd" and s[2] != SCHED_OTHER:
                policy = s[2]
                break
            time.sleep(0.002)
    finally:
        shell.kill()
        shell.wait()
    check(policy == SCHED_FIFO, "pd in batch mode without -nrt, run as root, takes SCHED_FIFO "
          "(policy %s): the check below can fail here" % policy)

    out = os.path.join(work, "render")
    proc = subprocess.Popen([os.path.join(os.path.abspath(args.build), "ictusd"), "render",
                             "--score", args.score, "--out", out, "--bvh-rate", "0",
                             "--tips-rate", "0", "--wav", os.path.join(out, "performance.wav")],
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    sampled = []
    sampler = threading.Thread(target=lambda: sampled.extend(policies_while(proc, "pd")))
    sampler.start()
    try:
        _, err = proc.communicate(timeout=600)
    finally:
        if proc.poll() is None:
            proc.kill()
        sampler.join()
    check(proc.returncode == 0, "ictusd render --wav ran: %s" % err[-2000:])
    check(len(sampled) >= 5, "the pd that ictusd spawned was seen rendering (%d samples)"
          % len(sampled))
    check(set(sampled) == {SCHED_OTHER}, "ictusd's batch pd ran as SCHED_OTHER throughout "
          "(policies seen: %s)" % sorted(set(sampled)))
    print("ok")


if __name__ == "__main__":
    main()
