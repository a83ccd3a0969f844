"""ictus against its peers, side by side in one run (docs/benchmarks.md). Run through
bench/peers/run_peers.sh, which sets up the peers' virtual environment.

Every round runs each case once, ictus and peers alternating, so that the load
of a shared machine falls on all of them alike; the table keeps the best round
of each case and the median of the per-round ratios. Times are CPU times (user
+ sys of the process, or process time of the stepping loop for MuJoCo): on a
shared 2-core machine wall time mostly measures the scheduler.

Drum, ns per mode per sample, 48 kHz, in `pd -batch` (the CPU time of an
otherwise identical empty patch is subtracted):
  ictus    [membrane~ N] + [contact~]: a 10 kg stick (stiffness 1e6) hit in at
           0.5 m/s every 100 ms at the same spot and kept pressed (in contact
           ~100 % of the time); the first outlet listened to by [env~]; the AVX2+FMA
           kernel (ICTUS_MEMBRANE_KERNEL=avx2: the run-time choice is AVX-512 on
           some CPUs, and the target is AVX2's), and with
           ICTUS_MEMBRANE_KERNEL=generic (the portable SSE2 kernel)
  stereo   the same with both outlets listened to (the second pickup computed)
  50 g     the same hits with contact~'s default 50 g stick (same tip): a drumstick,
           which bounces off (in contact ~9 % of the samples, solved ~20 %)
  floor    the machine's memory floor for that kernel (bench_membrane_core --floor N,
           when built): the loads and stores of a pressed-stick pass, adds only
  before   the same patch with another build's Pd library (--before DIR), if given,
           with the run-time selected kernel and with the generic one, and its 50 g case
  bp~      N vanilla [bp~ f 10] fed by one [noise~]
  SDT      the Sound Design Toolkit's impact interactor + modal resonator
           (peer_sdt.py, pysdt from PyPI: SDT's Pd externals are not packaged);
           outside Pd, per-sample Python overhead removed by difference
Performer, real-time factor (simulated s / CPU s):
  track    `ictusd track --mode joint --mocap 80_13.bvh --quiet` (the CMU clip,
           1 ms steps); the CPU of a 10 ms run (start-up: reading the clip,
           learning limits) is subtracted, as MuJoCo's timing has no start-up
  MuJoCo   dm_control's CMU humanoid, 56 DoF, root fixed, 1 ms (peer_mujoco.py)
  render   `ictusd render` of the default score, --bvh-rate 0 --tips-rate 0
           (start-up included)
  kit      the same with `--kit standard --score examples/scores/kit.txt`
  groove   the same with `--kit full --score examples/scores/groove.txt` (hands and
           the kick's foot on the pedal)
  before   with --before-ictusd FILE, another ictusd's track and render in the
           same rounds (before / after a change, alternating)

Usage: bench_peers.py BUILD --python VENV_PYTHON [--rounds R] [--sizes 64,256,...]
       [--before DIR] [--before-ictusd FILE] [--bvh FILE] [--json FILE]
       [--skip drum,performer,sdt]"""
import argparse
import datetime
import json
import os
import platform
import re
import resource
import shutil
import statistics
import subprocess
import tempfile

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
SR = 48000

ap = argparse.ArgumentParser()
ap.add_argument("build")
ap.add_argument("--python", required=True, help="the peers' venv python")
ap.add_argument("--rounds", type=int, default=3)
ap.add_argument("--sizes", default="64,256,1024,4096")
ap.add_argument("--before", help="another build's Pd library folder (build/ictus) to compare")
ap.add_argument("--before-ictusd", help="another ictusd whose track and render run in the same rounds")
ap.add_argument("--bvh", default=os.path.join(ROOT, "..", "shared", "data", "cmu", "80_13.bvh"))
ap.add_argument("--mujoco-seconds", type=float, default=20.0)
ap.add_argument("--json", help="write every raw run here")
ap.add_argument("--skip", default="", help="comma list of: drum, performer, sdt, bp")
args = ap.parse_args()
build = os.path.abspath(args.build)
lib = os.path.join(build, "ictus")
ictusd = os.path.join(build, "ictusd")
floor_bin = os.path.join(build, "bench", "core", "bench_membrane_core")
skip = set(s for s in args.skip.split(",") if s)
sizes = [int(s) for s in args.sizes.split(",")]
work = tempfile.mkdtemp(prefix="ictus-peers-")
raw = []


def child_cpu():
    u = resource.getrusage(resource.RUSAGE_CHILDREN)
    return u.ru_utime + u.ru_stime


def run_cpu(cmd, env=None):
    """Runs cmd; returns (CPU seconds of the child, stdout)."""
    before = child_cpu()
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                       env=env, timeout=1800)
    cpu = child_cpu() - before
    if p.returncode != 0:
        raise SystemExit("%s failed (%d):\n%s%s" % (" ".join(cmd), p.returncode, p.stdout,
                                                   p.stderr[-3000:]))
    return cpu, p.stdout + p.stderr


# ---------------------------------------------------------------- the drum in Pd

def patch(path, seconds, body):
    lines = ["#N canvas 0 0 600 400 12;", "#X declare -path %s;" % path,
             "#X obj 10 10 loadbang;",                          # 0
             "#X msg 10 40 \\; pd dsp 1;",                      # 1
             "#X obj 10 70 delay %.17g;" % (seconds * 1000.0),  # 2
             "#X msg 10 100 \\; pd quit;",                      # 3
             "#X obj 10 130 noise~;",                           # 4
             "#X connect 0 0 1 0;", "#X connect 0 0 2 0;", "#X connect 2 0 3 0;"]
    body(lines)
    return "\n".join(lines) + "\n"


def pd_run(text, name, env=None):
    path = os.path.join(work, name + ".pd")
    with open(path, "w") as f:
        f.write(text)
    cpu, out = run_cpu(["pd", "-nogui", "-nosound", "-batch", "-nrt", "-stderr", "-r", str(SR),
                        "-open", path], env=env)
    if "error" in out.lower() or "couldn't" in out:
        raise SystemExit("%s: pd said:\n%s" % (name, out))
    return cpu


def ictus_patch(path, n, seconds, stereo=False, mass=10):
    def body(lines):
        lines += ["#X obj 200 10 membrane~ peers-drum;",
                  "#X msg 200 40 modes %d \\, t60 60 \\, hfdamp 0 \\, strike 0.3 0 0.01;" % n,
                  "#X connect 0 0 6 0;", "#X connect 6 0 5 0;",
                  "#X obj 300 10 contact~ peers-drum;",
                  "#X obj 300 40 metro 100;",
                  "#X msg 300 70 mass %g \\, stiffness 1e+06 \\, hit 0.5 0.3 0;" % mass,
                  "#X connect 0 0 8 0;", "#X connect 8 0 9 0;", "#X connect 9 0 7 0;",
                  "#X obj 200 100 env~ 4096;", "#X connect 5 0 10 0;"]
        if stereo:
            lines += ["#X obj 260 100 env~ 4096;", "#X connect 5 1 11 0;"]
    return patch(path, seconds, body)


def bp_patch(n, seconds):
    def body(lines):
        for k in range(n):
            lines.append("#X obj %d %d bp~ %g 10;" % (200 + k % 40 * 10, 10 + k // 40, 100 + 5 * k))
            lines.append("#X connect 4 0 %d 0;" % (5 + k))
    return patch(lib, seconds, body)


def drum_seconds(n, mode_samples):
    return max(1.0, min(120.0, mode_samples / (n * SR)))


def drum_round(r, results):
    for n in sizes:
        s_ictus = drum_seconds(n, 1.0e9)   # ~0.2-0.5 s of CPU for ictus
        s_bp = drum_seconds(n, 2.0e8)      # ~0.4 s for bp~
        empties = {}
        for s in sorted({s_ictus, s_bp}):
            empties[s] = pd_run(patch(lib, s, lambda lines: None), "empty-%d" % n)
        generic = dict(os.environ, ICTUS_MEMBRANE_KERNEL="generic")
        avx2 = dict(os.environ, ICTUS_MEMBRANE_KERNEL="avx2")
        cases = [("ictus avx2", lambda: pd_run(ictus_patch(lib, n, s_ictus), "ictus-%d" % n, avx2),
                  s_ictus),
                 ("ictus generic", lambda: pd_run(ictus_patch(lib, n, s_ictus), "generic-%d" % n,
                                                  generic), s_ictus),
                 ("ictus stereo", lambda: pd_run(ictus_patch(lib, n, s_ictus, stereo=True),
                                                 "stereo-%d" % n, avx2), s_ictus),
                 ("ictus 50 g", lambda: pd_run(ictus_patch(lib, n, s_ictus, mass=0.05),
                                               "stick-%d" % n, avx2), s_ictus)]
        if args.before:
            before = os.path.abspath(args.before)
            cases.append(("before avx2", lambda: pd_run(ictus_patch(before, n, s_ictus),
                                                        "before-%d" % n), s_ictus))
            cases.append(("before generic",
                          lambda: pd_run(ictus_patch(before, n, s_ictus), "before-generic-%d" % n,
                                         generic), s_ictus))
            cases.append(("before 50 g",
                          lambda: pd_run(ictus_patch(before, n, s_ictus, mass=0.05),
                                         "before-stick-%d" % n), s_ictus))
        if "bp" not in skip:
            cases.append(("bp~", lambda: pd_run(bp_patch(n, s_bp), "bp-%d" % n), s_bp))
        for name, fn, s in cases:
            cpu = fn()
            ns = (cpu - empties[s]) * 1e9 / (n * SR * s)
            results.setdefault((name, n), []).append(ns)
            raw.append({"round": r, "case": name, "modes": n, "audio_s": s, "cpu_s": cpu,
                        "empty_cpu_s": empties[s], "ns_per_mode_sample": ns})
        if os.access(floor_bin, os.X_OK):
            # The machine's memory floor for the kernel with a stick pressed (what it
            # loads and stores, adds only; bench/core/bench_membrane.c), in the same round.
            _, out = run_cpu([floor_bin, "--floor", str(n), "0.5"])
            floor_ns = float(out.strip().splitlines()[-1])
            results.setdefault(("floor", n), []).append(floor_ns)
            raw.append({"round": r, "case": "memory floor", "modes": n,
                        "ns_per_mode_sample": floor_ns})
        if "sdt" not in skip:
            sec = max(0.2, min(2.0, 2.5e7 / (n * SR)))
            _, out = run_cpu([args.python, os.path.join(ROOT, "bench", "peers", "peer_sdt.py"),
                              str(n), str(sec)])
            j = json.loads(out.strip().splitlines()[-1])
            results.setdefault(("SDT", n), []).append(j["ns_per_mode_sample"])
            raw.append(dict(j, round=r, case="SDT"))


# ---------------------------------------------------------------- the performer

mujoco_version = [""]


def track_run(r, results, binary, key, case):
    cpu, out = run_cpu([binary, "track", "--mode", "joint", "--mocap", args.bvh, "--quiet"])
    m = re.search(r"([0-9.]+) s simulated, realtime factor ([0-9.]+)", out)
    if not m:
        raise SystemExit("ictusd track printed no realtime factor:\n" + out)
    sim, wall_rtf = float(m.group(1)), float(m.group(2))
    cpu0, _ = run_cpu([binary, "track", "--mode", "joint", "--mocap", args.bvh, "--quiet",
                       "--duration", "0.01"])
    rtf = sim / max(cpu - cpu0, 1e-9)
    results.setdefault(key, []).append(rtf)
    raw.append({"round": r, "case": case, "sim_s": sim, "cpu_s": cpu,
                "startup_cpu_s": cpu0, "rtf_cpu": rtf, "rtf_wall_printed": wall_rtf})


KIT_SCORE = os.path.join(ROOT, "examples", "scores", "kit.txt")
GROOVE_SCORE = os.path.join(ROOT, "examples", "scores", "groove.txt")


def render_run(r, results, binary, key, case, extra=()):
    out_dir = os.path.join(work, "render-%d" % r)
    cpu, out = run_cpu([binary, "render", "--out", out_dir, "--bvh-rate", "0", "--tips-rate", "0"]
                       + list(extra))
    m = re.search(r"render: ([0-9.]+) s simulated in ([0-9.]+) s \(([0-9.]+)x real time\)", out)
    if not m:
        raise SystemExit("ictusd render printed no speed:\n" + out)
    sim = float(m.group(1))
    results.setdefault(key, []).append(sim / cpu)
    raw.append({"round": r, "case": case, "sim_s": sim, "cpu_s": cpu,
                "rtf_cpu": sim / cpu, "rtf_wall_printed": float(m.group(3))})
    shutil.rmtree(out_dir, ignore_errors=True)


def track_round(r, results):
    if args.before_ictusd:
        track_run(r, results, args.before_ictusd, "track_before", "before: ictusd track --mode joint")
    track_run(r, results, ictusd, "track", "ictusd track --mode joint")

    _, out = run_cpu([args.python, os.path.join(ROOT, "bench", "peers", "peer_mujoco.py"),
                      str(args.mujoco_seconds)])
    j = json.loads(out.strip().splitlines()[-1])
    if not j["finite"]:
        raise SystemExit("MuJoCo diverged: %s" % j)
    results.setdefault("mujoco", []).append(j["sim_s"] / j["cpu_s"])
    mujoco_version[0] = "%s (dm_control %s)" % (j["mujoco"], j["dm_control"])
    raw.append(dict(j, round=r, case="MuJoCo CMU humanoid", rtf_cpu=j["sim_s"] / j["cpu_s"],
                    rtf_wall=j["sim_s"] / j["wall_s"]))

    if args.before_ictusd:
        render_run(r, results, args.before_ictusd, "render_before", "before: ictusd render")
    render_run(r, results, ictusd, "render", "ictusd render")
    render_run(r, results, ictusd, "render_kit", "ictusd render --kit standard, kit.txt",
               ["--kit", "standard", "--score", KIT_SCORE])
    render_run(r, results, ictusd, "render_groove", "ictusd render --kit full, groove.txt",
               ["--kit", "full", "--score", GROOVE_SCORE])


# ---------------------------------------------------------------- main

def loadavg():
    with open("/proc/loadavg") as f:
        return " ".join(f.read().split()[:3])


def cpu_model():
    """The model name and what tells two machines of one name apart: "AMD EPYC" has
    been a Zen 1 (family 23, 256-bit vectors run as two 128-bit halves) and a Zen 4
    (family 25) here, with ~2x between them; the family, model, the widest vectors
    and the L1d size say which (docs/benchmarks.md)."""
    info = {}
    with open("/proc/cpuinfo") as f:
        for line in f:
            if ":" in line:
                key, value = (t.strip() for t in line.split(":", 1))
                info.setdefault(key, value)
            elif not line.strip() and info:
                break  # the first processor is enough
    name = info.get("model name", platform.processor())
    flags = info.get("flags", "").split()
    vec = "avx512" if "avx512f" in flags else "avx2" if "avx2" in flags else "sse2"
    extra = ["family %s model %s stepping %s" % (info.get("cpu family", "?"), info.get("model", "?"),
                                                  info.get("stepping", "?")), vec]
    if "cpu MHz" in info:
        extra.append("%.0f MHz" % float(info["cpu MHz"]))
    try:
        with open("/sys/devices/system/cpu/cpu0/cache/index0/size") as f:
            extra.append("L1d " + f.read().strip())
    except OSError:
        pass
    return "%s (%s)" % (name, ", ".join(extra))


pd_version = subprocess.run(["pd", "-version"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True).stdout.split()[0]
info = {"date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "machine": "%s, %d cpu, %s" % (cpu_model(), os.cpu_count(), platform.platform()),
        "pd": pd_version, "load_before": loadavg(), "rounds": args.rounds}
print("date: %(date)s\nmachine: %(machine)s\n%(pd)s; load before: %(load_before)s" % info,
      flush=True)
results = {}
for r in range(args.rounds):
    if "drum" not in skip:
        drum_round(r, results)
    if "performer" not in skip:
        track_round(r, results)
    print("round %d done, load %s" % (r + 1, loadavg()), flush=True)
info["load_after"] = loadavg()


def per_round_ratio(a, b):
    """Median over rounds of a[r] / b[r] (both lists in round order)."""
    pairs = [(x / y) for x, y in zip(a, b) if y > 0]
    return statistics.median(pairs) if pairs else float("nan")


print("\nDrum in Pd, ns per mode per sample (best round), "
      "and peer / ictus avx2 (median of the per-round ratios)")
cols = (["ictus avx2", "ictus generic", "ictus stereo", "ictus 50 g"]
        + (["before avx2", "before generic", "before 50 g"] if args.before else [])
        + ([] if "bp" in skip else ["bp~"]) + ([] if "sdt" in skip else ["SDT"]))
if "drum" not in skip:
    print("%6s " % "N" + " ".join("%14s" % c for c in cols) + "   peer / ictus avx2")
    for n in sizes:
        row = ["%14.3f" % min(results[(c, n)]) for c in cols]
        ratios = []
        for c in cols[1:]:
            ratio = per_round_ratio(results[(c, n)], results[("ictus avx2", n)])
            ratios.append("%s %.1fx" % (c, ratio))
        print("%6d " % n + " ".join(row) + "   " + ", ".join(ratios))
    if ("floor", sizes[0]) in results:
        print("\nThe machine's memory floor for the kernel with a stick pressed (7 floats loaded, "
              "2 stored\nper mode and sample, adds only; bench_membrane_core --floor), best round, "
              "and ictus / floor\n(median of the per-round ratios)")
        for n in sizes:
            f = results[("floor", n)]
            print("%6d %14.3f   avx2 %.2fx, generic %.2fx" % (
                n, min(f), per_round_ratio(results[("ictus avx2", n)], f),
                per_round_ratio(results[("ictus generic", n)], f)))
    if 1024 in sizes:
        print("Targets at 1024 modes, the 10 kg pressed stick: avx2 %.3f (target <= 0.20), "
              "generic %.3f (target <= 0.5), best rounds" % (
                  min(results[("ictus avx2", 1024)]), min(results[("ictus generic", 1024)])))
if "performer" not in skip:
    t, mj, rd = results["track"], results["mujoco"], results["render"]
    print("\nPerformer, real-time factor on CPU time (best round; all rounds)")
    print("  ictusd track --mode joint (CMU 80_13): %.1fx  [%s]" % (
        max(t), ", ".join("%.1f" % v for v in t)))
    print("  MuJoCo %s CMU humanoid, root fixed: %.1fx  [%s]" % (
        mujoco_version[0], max(mj), ", ".join("%.1f" % v for v in mj)))
    print("  ratio track / MuJoCo: best %.2f, median of rounds %.2f (target >= 1.25)" % (
        max(t) / max(mj), per_round_ratio(t, mj)))
    print("  ictusd render, default score:          %.1fx  [%s] (target >= 25)" % (
        max(rd), ", ".join("%.1f" % v for v in rd)))
    print("  ratio render / MuJoCo: median of rounds %.2f (target >= 1.25)" % per_round_ratio(rd, mj))
    rk = results["render_kit"]
    print("  ictusd render --kit standard, examples/scores/kit.txt: %.1fx  [%s]; "
          "ratio to MuJoCo, median of rounds %.2f (target >= 1.0)" % (
              max(rk), ", ".join("%.1f" % v for v in rk), per_round_ratio(rk, mj)))
    rg = results["render_groove"]
    print("  ictusd render --kit full, examples/scores/groove.txt: %.1fx  [%s]; "
          "ratio to MuJoCo, median of rounds %.2f (target >= 0.8)" % (
              max(rg), ", ".join("%.1f" % v for v in rg), per_round_ratio(rg, mj)))
    if args.before_ictusd:
        tb, rb = results["track_before"], results["render_before"]
        print("  before (%s): track %.1fx [%s], ratio track / MuJoCo median %.2f; "
              "render %.1fx [%s]" % (args.before_ictusd, max(tb), ", ".join("%.1f" % v for v in tb),
                                     per_round_ratio(tb, mj), max(rb),
                                     ", ".join("%.1f" % v for v in rb)))
        print("  after / before, median of rounds: track %.3f, render %.3f" % (
            per_round_ratio(t, tb), per_round_ratio(rd, rb)))
print("\nload after: %s" % info["load_after"])
if args.json:
    with open(args.json, "w") as f:
        json.dump({"info": info, "runs": raw}, f, indent=1)
    print("raw runs: %s" % args.json)
shutil.rmtree(work, ignore_errors=True)
