#!/usr/bin/env python3
"""A human hand (docs/perform.md, "A human hand"), played by the real `ictusd render`:
32 repeated mf right-hand notes at 120 bpm (0.5 s apart), each note's first strike in strikes.csv.
- humanize 0 (the default, and written `--humanize 0`): two renders byte-identical in every file,
  and the strikes as regular as the physics alone makes them (timing SD < 0.1 ms);
- at the documented default amount 1: timing SD 1-5 ms and impact-speed CV 2-8 % (the acceptance);
  the same seed gives byte-identical renders, another seed different strikes;
- the spreads grow with the amount over 0.5, 1, 2;
- `R+L` at amount 1: the two hands' strikes no longer land together (each draws its own timing).
The timing SD is the SD of (strike time - 0.5 s x k): the plan's fixed offset cancels.

    python3 tests/perform/test_humanize.py --ictusd build/ictusd
"""
import argparse
import csv
import filecmp
import os
import statistics
import subprocess
import sys

SCORE = "tempo 120\ndynamics mf\nrepeat 32\nR\nend\n"
BOTH = "tempo 120\ndynamics mf\nrepeat 16\nR+L\nend\n"
PERIOD_S = 0.5
TIMING_MS = (1.0, 5.0)  # the acceptance at the default amount
CV_PCT = (2.0, 8.0)


def render(ictusd, workdir, name, text, args):
    # One score file per text: render.json names it, so equal renders name the same file.
    os.makedirs(workdir, exist_ok=True)
    path = os.path.join(workdir, "both.txt" if text == BOTH else "repeated.txt")
    with open(path, "w") as f:
        f.write(text)
    out = os.path.join(workdir, name)
    cmd = [ictusd, "render", "--score", path, "--out", out, "--force", "--bvh-rate", "0"] + args
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, timeout=600)
    return out


def first_strikes(out, hand):
    with open(os.path.join(out, "strikes.csv")) as f:
        rows = [r for r in csv.DictReader(f) if r["bounce"] == "0" and r["hand"] == hand]
    return [float(r["time_s"]) for r in rows], [float(r["normal_velocity_mps"]) for r in rows]


def spreads(out, problems, what):
    t, v = first_strikes(out, "1")
    if len(t) != 32:
        problems.append("%s: %d first strikes of the right hand, want 32" % (what, len(t)))
        return float("nan"), float("nan")
    sd_ms = statistics.stdev(ti - PERIOD_S * k for k, ti in enumerate(t)) * 1000.0
    cv_pct = statistics.stdev(v) / statistics.mean(v) * 100.0
    print("%-12s timing SD %.3f ms, impact speed %.3f m/s CV %.2f %%"
          % (what, sd_ms, statistics.mean(v), cv_pct))
    return sd_ms, cv_pct


def same_files(a, b):
    names = sorted(os.listdir(a))
    if names != sorted(os.listdir(b)):
        return False
    return all(filecmp.cmp(os.path.join(a, n), os.path.join(b, n), shallow=False)
               for n in names if os.path.isfile(os.path.join(a, n)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--ictusd", required=True)
    ap.add_argument("--workdir", default="humanize-out")
    ap.add_argument("--amounts", default="0.5,1,2",
                    help="amounts whose spreads must grow in turn (1 always played)")
    a = ap.parse_args()
    problems = []
    r = lambda name, args, text=SCORE: render(a.ictusd, a.workdir, name, text, args)
    zero = [r("zero-a", []), r("zero-b", ["--humanize", "0", "--seed", "7"])]
    if not same_files(*zero):
        problems.append("humanize 0: two renders (default; --humanize 0 --seed 7) differ")
    sd0, _ = spreads(zero[0], problems, "amount 0")
    if not sd0 < 0.1:
        problems.append("humanize 0: timing SD %.3f ms, want the physics' own (< 0.1 ms)" % sd0)
    by_amount = {}
    amounts = sorted(set(a.amounts.split(",")) | {"1"}, key=float)
    for amount in amounts:
        out = r("amount-" + amount, ["--humanize", amount])
        by_amount[amount] = spreads(out, problems, "amount " + amount)
    sd1, cv1 = by_amount["1"]
    if not TIMING_MS[0] <= sd1 <= TIMING_MS[1]:
        problems.append("amount 1: timing SD %.3f ms, want %g-%g ms" % (sd1, *TIMING_MS))
    if not CV_PCT[0] <= cv1 <= CV_PCT[1]:
        problems.append("amount 1: impact-speed CV %.2f %%, want %g-%g %%" % (cv1, *CV_PCT))
    for lo, hi in zip(amounts, amounts[1:]):
        for i, what in ((0, "timing SD"), (1, "impact-speed CV")):
            if not by_amount[hi][i] > by_amount[lo][i]:
                problems.append("%s does not grow from amount %s (%.3f) to %s (%.3f)"
                                % (what, lo, by_amount[lo][i], hi, by_amount[hi][i]))
    again = r("amount-1-again", ["--humanize", "1", "--seed", "1"])
    if not same_files(os.path.join(a.workdir, "amount-1"), again):
        problems.append("humanize 1, seed 1 twice: the renders differ")
    other = r("seed-2", ["--humanize", "1", "--seed", "2"])
    if first_strikes(other, "1") == first_strikes(again, "1"):
        problems.append("seeds 1 and 2 give the same strikes")
    spreads(other, problems, "seed 2")
    # The statement: `humanize 1` plays as --humanize 1; --humanize 0 replaces it.
    written = os.path.join(a.workdir, "written.txt")
    with open(written, "w") as f:
        f.write("humanize 1\n" + SCORE)
    for name, args, ref in (("written", [], "amount-1"), ("written-0", ["--humanize", "0"], "zero-a")):
        out = os.path.join(a.workdir, name)
        subprocess.run([a.ictusd, "render", "--score", written, "--out", out, "--force",
                        "--bvh-rate", "0"] + args, check=True, stdout=subprocess.DEVNULL)
        if first_strikes(out, "1") != first_strikes(os.path.join(a.workdir, ref), "1"):
            problems.append("the score's humanize 1 with %s does not play as %s" % (args, ref))
    with open(written, "w") as f:
        f.write(SCORE + "humanize 5\n")
    bad = subprocess.run([a.ictusd, "render", "--score", written, "--out",
                          os.path.join(a.workdir, "bad"), "--force"], stdout=subprocess.PIPE,
                         stderr=subprocess.STDOUT, text=True)
    if bad.returncode == 0 or "written.txt:6:10: humanize 5 is out of range" not in bad.stdout:
        problems.append("humanize 5 on line 6: not refused naming the line: " + bad.stdout[-200:])
    both = r("both", ["--humanize", "1"], BOTH)
    right, left = first_strikes(both, "1")[0], first_strikes(both, "0")[0]
    if len(right) != 16 or len(left) != 16:
        problems.append("R+L: %d right and %d left first strikes, want 16 each"
                        % (len(right), len(left)))
    else:
        apart = [abs(x - y) * 1000.0 for x, y in zip(right, left)]
        print("R+L at amount 1: hands %.3f ms apart on average" % statistics.mean(apart))
        if not statistics.mean(apart) > 1.0:
            problems.append("R+L: the hands land %.3f ms apart on average, want > 1 ms"
                            % statistics.mean(apart))
    for p in problems:
        print("FAIL: " + p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
