"""membrane~ in real Pd: nanoseconds per mode per sample, against a bank of
vanilla [bp~] filters (one per mode), all in `pd -batch` (as fast as the CPU
goes). For each case a patch is generated, pd runs it for S seconds of audio,
and the wall time of an otherwise identical empty patch is subtracted:

    ns per mode-sample = (t_case - t_empty) / (N * sr * S)

with t the CPU time (user + sys) of the pd process.

Cases, for N = 16, 256, 1024, 4096:
  free     one membrane~ with N modes, struck once, ringing (t60 60 s, hfdamp 0)
  contact  the same with a contact~ in contact 99.9 % of the time: a 10 kg stick
           with a soft tip (k 1e6) hit in at 0.5 m/s every 100 ms (each hit
           computes the mode weights at the point, O(N) Bessel values; 10 per
           second cost little)
  roll     a 0.05 kg stick hit at 1 m/s every 5 ms, each time at a new spot
           (r/a 0.2 .. 0.7, so no hit reuses cached shapes) (in contact 99 % of the
           time too; 200 hits per second, so the per-hit cost shows)
  bp~      N [bp~] fed by one [noise~] (noise~ is in the empty patch too)
Best (smallest) of R runs each. Usage: bench_pd.py BUILD_DIR [--runs R]"""
import shutil

import pdbench
from pdbench import bp_bank

args, bench = pdbench.from_args("ictus-bench-", seconds=False)
sr, work = args.sr, bench.work
patch, run = bench.patch, bench.run


def empty(lines, i):
    pass


def membrane(n, hits=None):
    """hits: None (ringing freely) or (setup message for contact~, metro period ms)."""
    def body(lines, i):
        lines.append("#X obj 200 10 membrane~ bench-drum;")  # i
        lines.append("#X msg 200 40 modes %d \\, t60 60 \\, hfdamp 0 \\, strike 0.3 0 0.01;" % n)
        lines.append("#X connect 0 0 %d 0;" % (i + 1))
        lines.append("#X connect %d 0 %d 0;" % (i + 1, i))
        if hits:
            message, period_ms = hits
            lines.append("#X obj 300 10 contact~ bench-drum;")  # i+2
            lines.append("#X obj 300 40 metro %g;" % period_ms)  # i+3
            lines.append("#X msg 300 70 %s;" % message)  # i+4
            lines.append("#X connect 0 0 %d 0;" % (i + 3))
            lines.append("#X connect %d 0 %d 0;" % (i + 4, i + 2))
            if "$1" in message:
                # a new spot every hit (r/a 0.2 .. 0.7): the shapes cannot come
                # from the cache, so each hit computes its O(N) Bessel values
                lines.append("#X obj 300 100 random 1000;")  # i+5
                lines.append("#X obj 300 130 expr 0.2 + $f1 / 2000;")  # i+6
                lines.append("#X connect %d 0 %d 0;" % (i + 3, i + 5))
                lines.append("#X connect %d 0 %d 0;" % (i + 5, i + 6))
                lines.append("#X connect %d 0 %d 0;" % (i + 6, i + 4))
            else:
                lines.append("#X connect %d 0 %d 0;" % (i + 3, i + 4))
    return body


PRESSED = ("mass 10 \\, stiffness 1e+06 \\, hit 0.5 0.3 0", 100)
ROLL = ("hit 1 \\$1 0", 5)




print("membrane~ in Pd: CPU ns per mode per sample, sr %d Hz, best of %d runs" % (sr, args.runs))
print("%6s %8s %10s %10s %10s %10s" % ("N", "audio s", "free", "contact", "roll", "bp~"))
for n in [int(s) for s in args.sizes.split(",")]:
    # about 1e9 mode-samples per case, at least 2 s and at most 120 s of audio
    seconds = max(2.0, min(120.0, 1.0e9 / (n * sr)))
    t_empty = run(patch(seconds, empty), "empty-%d" % n)
    row = []
    for name, body in (("free", membrane(n)), ("contact", membrane(n, PRESSED)),
                       ("roll", membrane(n, ROLL)), ("bp", bp_bank(n))):
        t = run(patch(seconds, body), "%s-%d" % (name, n))
        row.append((t - t_empty) * 1e9 / (n * sr * seconds))
    print("%6d %8.1f %10.3f %10.3f %10.3f %10.3f" % ((n, seconds) + tuple(row)), flush=True)
shutil.rmtree(work, ignore_errors=True)
