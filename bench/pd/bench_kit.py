"""A kit in real Pd: what a snare (wires on), a tom, a floor tom and a timpani cost, each a
membrane~ at its preset's default mode count with its own contact~, all ringing (each hit
by a 14 g stick at 3 m/s every 250 ms, staggered), in `pd -batch` at 48 kHz:

    share of one core = (t_kit - t_empty) / S
    ns per mode-sample = (t_kit - t_empty) / (N_total * sr * S)

against a bank of N_total vanilla [bp~] in the same run (bench_pd.py's reference), with t
the CPU time (user + sys) of pd, best of R runs. The mode counts are read from each
membrane~'s `print` (a snare's: the batter's and the snare head's). Usage: bench_kit.py BUILD_DIR [--runs R] [--seconds S]"""
import os
import re
import shutil
import subprocess

import pdbench
from pdbench import bp_bank

KIT = os.environ.get("ICTUS_BENCH_KIT", "snare,tom,floor-tom,timpani").split(",")

args, bench = pdbench.from_args("ictus-bench-kit-")
work = bench.work


def kit(lines, i):
    for k, preset in enumerate(KIT):
        j = i + 4 * k
        name = "bench-kit-%d" % k
        lines.append("#X obj %d 10 membrane~ %s;" % (200 + 150 * k, name))  # j
        lines.append("#X msg %d 40 preset %s \\, print;" % (200 + 150 * k, preset))  # j+1
        lines.append("#X obj %d 70 contact~ %s;" % (200 + 150 * k, name))  # j+2
        # staggered: drum k is hit 62.5 k ms into each 250 ms
        lines.append("#X msg %d 100 mass 0.014 \\, hit 3 0.3 0;" % (200 + 150 * k))  # j+3
        lines.append("#X connect 0 0 %d 0;" % (j + 1))
        lines.append("#X connect %d 0 %d 0;" % (j + 1, j))
        lines.append("#X connect %d 0 %d 0;" % (j + 3, j + 2))
    base = i + 4 * len(KIT)
    lines.append("#X obj 10 200 metro 62.5;")  # base
    lines.append("#X obj 10 230 f;")  # base+1
    lines.append("#X obj 10 260 + 1;")  # base+2
    lines.append("#X obj 10 290 mod %d;" % len(KIT))  # base+3
    lines.append("#X obj 10 320 sel %s;" % " ".join(str(k) for k in range(len(KIT))))  # base+4
    lines.append("#X connect 0 0 %d 0;" % base)
    lines.append("#X connect %d 0 %d 0;" % (base, base + 1))
    lines.append("#X connect %d 0 %d 0;" % (base + 1, base + 2))
    lines.append("#X connect %d 0 %d 0;" % (base + 2, base + 3))
    lines.append("#X connect %d 0 %d 1;" % (base + 3, base + 1))
    lines.append("#X connect %d 0 %d 0;" % (base + 3, base + 4))
    for k in range(len(KIT)):
        lines.append("#X connect %d %d %d 0;" % (base + 4, k, i + 4 * k + 3))


def mode_counts():
    """Each kit drum's mode count, from membrane~'s print in a short run."""
    path = os.path.join(work, "count.pd")
    with open(path, "w") as f:
        f.write(bench.patch(0.01, kit))
    err = subprocess.run(["pd", "-nogui", "-nosound", "-batch", "-stderr", "-r", str(args.sr),
                          "-open", path], capture_output=True, text=True, timeout=120).stderr
    counts = [int(m) for m in re.findall(r"membrane~ bench-kit-\d+: .*?, (\d+) modes,", err)]
    if len(counts) != len(KIT):
        raise SystemExit("could not read the mode counts:\n" + err[-2000:])
    # A snare's second head (membrane~ prints "snare head N modes") counts as modes too.
    for k, n in re.findall(r"membrane~ bench-kit-(\d+): snare head (\d+) modes", err):
        counts[int(k)] += int(n)
    return counts


counts = mode_counts()
total = sum(counts)
s = args.seconds
t_empty = bench.run(bench.patch(s, lambda lines, i: None), "empty")
t_kit = bench.run(bench.patch(s, kit), "kit")
t_bp = bench.run(bench.patch(s, bp_bank(total)), "bp")
ns_kit = (t_kit - t_empty) * 1e9 / (total * args.sr * s)
ns_bp = (t_bp - t_empty) * 1e9 / (total * args.sr * s)
print("kit in Pd, %d Hz, %g s of audio, best of %d runs" % (args.sr, s, args.runs))
print("modes: " + ", ".join("%s %d" % (p, n) for p, n in zip(KIT, counts)) + " (total %d)" % total)
print("share of one core: %.2f %%" % (100.0 * (t_kit - t_empty) / s))
print("ns per mode-sample: kit %.3f, bp~ %.3f: bp~ / kit %.1fx" % (ns_kit, ns_bp, ns_bp / ns_kit))
shutil.rmtree(work, ignore_errors=True)
