"""`ictusd render --wav` runs its batch pd without real-time priority (-nrt, docs/main-job.md).
Run as root, pd takes SCHED_FIFO unless told not to; a batch render never sleeps, so it would
hold a core against every ordinary process, and starve a live pd of the same priority, for as
long as it renders. Seen from outside, in /proc: the scheduling policy of the pd that ictusd
spawns, sampled while it renders, is SCHED_OTHER throughout. First, the control: pd started
here without -nrt (in real time, idle: it sleeps) takes SCHED_FIFO, so the check can fail on
this machine. Skipped (exit 77) where it does not (not root, or root without CAP_SYS_NICE, as
in a container): pd cannot take SCHED_FIFO there, and there is nothing to tell apart.

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
from ictus_tools.pdrun import make_workdir

SCHED_OTHER, SCHED_FIFO = 0, 1
CONTROL_S = 10.0  # the control pd sets its priority as it starts: within this, or never


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


def child_named(parent, name):
    """The pid of a child of parent whose command is name, or None: from the kernel's list
    of each of parent's threads' children, else (no such list) from a scan of /proc."""
    try:
        tasks = os.listdir("/proc/%d/task" % parent)
        with_list = os.path.exists("/proc/%d/task/%s/children" % (parent, tasks[0]))
    except (OSError, IndexError):
        return None
    if with_list:
        pids = []
        for tid in tasks:
            try:
                with open("/proc/%d/task/%s/children" % (parent, tid)) as f:
                    pids += [int(p) for p in f.read().split()]
            except OSError:
                pass
    else:
        pids = [int(e) for e in os.listdir("/proc") if e.isdigit()]
    for pid in pids:
        s = stat(pid)
        if s and s[0] == name and s[1] == parent:
            return pid
    return None


def policies_while(proc, name):
    """The policies of proc's child called name, sampled every 5 ms until proc ends (the
    child is looked for until found, then read alone)."""
    seen, pid = [], None
    while proc.poll() is None:
        s = stat(pid) if pid else None
        if s is None or s[1] != proc.pid:
            pid = child_named(proc.pid, name)
            s = stat(pid) if pid else None
        if s and s[0] == name:
            seen.append(s[2])
        time.sleep(0.005)
    return seen


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", required=True)
    ap.add_argument("--score", required=True)
    args = ap.parse_args()
    work = make_workdir("ictus-render-priority-")

    # The control: the same pd without -nrt, in real time on an empty patch (it sleeps
    # between ticks), takes SCHED_FIFO where this process may.
    patch = os.path.join(work, "idle.pd")
    with open(patch, "w") as f:
        f.write("#N canvas 0 0 200 200 12;\n")
    env = u.pd_spawning_env(work)
    shell = subprocess.Popen(["sh", "-c", 'exec "$0" -nogui -nosound -stderr -open "$1"', "pd",
                              patch], env=env, stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL)
    policy, t0 = None, time.time()
    try:
        while time.time() - t0 < CONTROL_S and shell.poll() is None:
            s = stat(shell.pid)
            if s and s[0] == "pd" and s[2] != SCHED_OTHER:
                policy = s[2]
                break
            time.sleep(0.005)
    finally:
        shell.kill()
        shell.wait()
    if policy is None:
        print("SKIP: pd without -nrt stays SCHED_OTHER here (not root, or no CAP_SYS_NICE): "
              "-nrt changes nothing to see")
        sys.exit(77)
    check(policy == SCHED_FIFO, "pd without -nrt takes SCHED_FIFO here (policy %d): the check "
          "below can fail" % policy)

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
