"""A kit in real Pd: each piece a membrane~ at its preset's default mode count with its own
contact~, all ringing (one piece hit every GAP ms, round robin, so each is hit every
GAP x pieces ms), in `pd -batch` at 48 kHz:

    share of one core = t_kit / S
    ns per mode-sample = t_kit / (N_total * sr * S)

against a bank of N_total vanilla [bp~] in the same run (bench_pd.py's reference), with t
the CPU time (user + sys) of pd, best of R runs. The mode counts are read from each
membrane~'s `print` (a snare's: the batter's and the snare head's).

Kits (--kit NAME, or a comma list of presets; ICTUS_BENCH_KIT sets the default):
  drums  snare (wires on), tom, floor-tom, timpani: a 14 g stick, contact~'s default
         tip, 3 m/s at r/a 0.3 (the default kit)
  full   ictusd's `full` kit: kick, snare (wires on), tom, tom, floor-tom, hihat, crash,
         ride; the sticks 13.8 g with the wood tip, the kick the pedal's felt beater (its
         effective mass, 54.7 g: docs/pedal.md), all at 3 m/s, each at its preset's
         strike point (r/a)
A comma list plays each preset as the drums kit does.
--each also runs every piece alone, hit as often as in the kit: its own share of a core.

Usage: bench_kit.py BUILD_DIR [--kit NAME|P1,P2,...] [--gap MS] [--each] [--runs R]
       [--seconds S]"""
import os
import re
import shutil
import subprocess

import pdbench
from pdbench import bp_bank

# A piece: (preset, contact~'s tip or None for its default, stick mass kg, r/a).
STICK, FELT_BEATER = 0.0138, 0.0547
KITS = {
    "drums": [(p, None, 0.014, 0.3) for p in ("snare", "tom", "floor-tom", "timpani")],
    "full": [("kick", "felt", FELT_BEATER, 0.15), ("snare", "wood", STICK, 0.3),
             ("tom", "wood", STICK, 0.3), ("tom", "wood", STICK, 0.3),
             ("floor-tom", "wood", STICK, 0.3), ("hihat", "wood", STICK, 0.7),
             ("crash", "wood", STICK, 0.9), ("ride", "wood", STICK, 0.6)],
}


def options(ap):
    ap.add_argument("--kit", default=os.environ.get("ICTUS_BENCH_KIT", "drums"),
                    help="drums, full, or a comma list of presets")
    ap.add_argument("--gap", type=float, default=62.5, help="ms from one hit to the next")
    ap.add_argument("--each", action="store_true", help="also each piece alone")


args, bench = pdbench.from_args("ictus-bench-kit-", extra=options)
work = bench.work
KIT = KITS.get(args.kit) or [(p, None, 0.014, 0.3) for p in args.kit.split(",")]
PERIOD = args.gap * len(KIT)  # ms between two hits of one piece


def kit(pieces, gap):
    """A patch body: the pieces, one hit every gap ms in turn."""
    def body(lines, i):
        for k, (preset, tip, mass, r) in enumerate(pieces):
            j = i + 4 * k
            name = "bench-kit-%d" % k
            x = 200 + 150 * k
            lines.append("#X obj %d 10 membrane~ %s;" % (x, name))  # j
            lines.append("#X msg %d 40 preset %s \\, print;" % (x, preset))  # j+1
            lines.append("#X obj %d 70 contact~ %s%s;" % (x, name, " " + tip if tip else ""))
            lines.append("#X msg %d 100 mass %g \\, hit 3 %g 0;" % (x, mass, r))  # j+3
            lines.append("#X connect 0 0 %d 0;" % (j + 1))
            lines.append("#X connect %d 0 %d 0;" % (j + 1, j))
            lines.append("#X connect %d 0 %d 0;" % (j + 3, j + 2))
        base = i + 4 * len(pieces)
        lines.append("#X obj 10 200 metro %g;" % gap)  # base
        lines.append("#X obj 10 230 f;")  # base+1
        lines.append("#X obj 10 260 + 1;")  # base+2
        lines.append("#X obj 10 290 mod %d;" % len(pieces))  # base+3
        lines.append("#X obj 10 320 sel %s;" % " ".join(str(k) for k in range(len(pieces))))
        lines.append("#X connect 0 0 %d 0;" % base)
        lines.append("#X connect %d 0 %d 0;" % (base, base + 1))
        lines.append("#X connect %d 0 %d 0;" % (base + 1, base + 2))
        lines.append("#X connect %d 0 %d 0;" % (base + 2, base + 3))
        lines.append("#X connect %d 0 %d 1;" % (base + 3, base + 1))
        lines.append("#X connect %d 0 %d 0;" % (base + 3, base + 4))
        for k in range(len(pieces)):
            lines.append("#X connect %d %d %d 0;" % (base + 4, k, i + 4 * k + 3))
    return body


def mode_counts():
    """Each piece's mode count, from membrane~'s print in a short run."""
    path = os.path.join(work, "count.pd")
    with open(path, "w") as f:
        f.write(bench.patch(0.01, kit(KIT, args.gap)))
    err = subprocess.run(["pd", "-nogui", "-nosound", "-batch", "-nrt", "-stderr", "-r", str(args.sr),
                          "-open", path], capture_output=True, text=True, timeout=120).stderr
    counts = [int(m) for m in re.findall(r"membrane~ bench-kit-\d+: .*?, (\d+) modes,", err)]
    if len(counts) != len(KIT) or "error" in err.lower():
        raise SystemExit("could not read the mode counts:\n" + err[-2000:])
    # A snare's second head (membrane~ prints "snare head N modes") counts as modes too.
    for k, n in re.findall(r"membrane~ bench-kit-(\d+): snare head (\d+) modes", err):
        counts[int(k)] += int(n)
    return counts


counts = mode_counts()
total = sum(counts)
s = args.seconds
t_kit = bench.dsp_time(kit(KIT, args.gap), "kit", s)
t_bp = bench.dsp_time(bp_bank(total), "bp", s)
alone = [bench.dsp_time(kit([piece], PERIOD), "piece-%d" % k, s)
         for k, piece in enumerate(KIT)] if args.each else []
ns_kit = t_kit * 1e9 / (total * args.sr * s)
ns_bp = t_bp * 1e9 / (total * args.sr * s)
print("kit in Pd, %d Hz, %g s of audio, best of %d runs; a hit every %g ms, each piece every "
      "%g ms" % (args.sr, s, args.runs, args.gap, PERIOD))
print("modes: " + ", ".join("%s %d" % (p[0], n) for p, n in zip(KIT, counts))
      + " (total %d)" % total)
print("share of one core: %.2f %%" % (100.0 * t_kit / s))
print("ns per mode-sample: kit %.3f, bp~ %.3f: bp~ / kit %.1fx" % (ns_kit, ns_bp, ns_bp / ns_kit))
if alone:
    shares = [100.0 * t / s for t in alone]
    print("each alone, share of one core: " + ", ".join(
        "%s %.2f %%" % (p[0], v) for p, v in zip(KIT, shares)) + " (sum %.2f %%)" % sum(shares))
shutil.rmtree(work, ignore_errors=True)
