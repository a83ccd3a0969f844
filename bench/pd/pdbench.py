"""What the Pd benchmarks share: a generated patch that switches DSP on at load and quits
after S seconds of audio, and the CPU time (user + sys) pd takes to run it in batch mode,
best of R runs. Used by bench_pd.py, bench_kit.py and bench_cascade.py."""
import argparse
import os
import resource
import subprocess
import tempfile


def from_args(prefix, seconds=True, extra=None):
    """The benchmarks' common command line (BUILD_DIR [--runs R] [--sr HZ] [--seconds S]),
    plus what extra(parser) adds, parsed, and a Bench on BUILD_DIR's Pd library in a new
    temporary folder."""
    ap = argparse.ArgumentParser()
    ap.add_argument("build")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--sr", type=int, default=48000)
    if seconds:
        ap.add_argument("--seconds", type=float, default=20.0)
    else:
        ap.add_argument("--sizes", default="16,256,1024,4096")
    if extra:
        extra(ap)
    args = ap.parse_args()
    lib = os.path.join(os.path.abspath(args.build), "ictus")
    return args, Bench(lib, args.sr, args.runs, tempfile.mkdtemp(prefix=prefix))


class Bench:
    def __init__(self, lib, sr, runs, work):
        self.lib, self.sr, self.runs, self.work = lib, sr, runs, work
        self.cpu_so_far = 0.0

    def patch(self, seconds, body):
        """body(lines, first_index) appends objects after the fixed header (loadbang 0, dsp
        message 1, delay 2, quit 3, noise~ 4); returns the patch text."""
        lines = ["#N canvas 0 0 600 400 12;", "#X declare -path %s;" % self.lib,
                 "#X obj 10 10 loadbang;",                     # 0
                 "#X msg 10 40 \\; pd dsp 1;",                 # 1
                 "#X obj 10 70 delay %.17g;" % (seconds * 1000.0),  # 2
                 "#X msg 10 100 \\; pd quit;",                 # 3
                 "#X obj 10 130 noise~;",                      # 4
                 "#X connect 0 0 1 0;", "#X connect 0 0 2 0;", "#X connect 2 0 3 0;"]
        body(lines, 5)
        return "\n".join(lines) + "\n"

    def run(self, text, name):
        """Best (smallest) CPU time (user + sys, s) of pd over the runs. CPU time rather than
        wall time: other processes on the machine then inflate the figures much less (they
        still share caches and memory bandwidth)."""
        path = os.path.join(self.work, name + ".pd")
        with open(path, "w") as f:
            f.write(text)
        best = None
        for _ in range(self.runs):
            usage = resource.getrusage(resource.RUSAGE_CHILDREN)
            self.cpu_so_far = usage.ru_utime + usage.ru_stime  # not other children run before
            proc = subprocess.Popen(["pd", "-nogui", "-nosound", "-batch", "-nrt", "-stderr", "-r",
                                     str(self.sr), "-open", path], stdout=subprocess.PIPE,
                                    stderr=subprocess.PIPE, text=True)
            _, err = proc.communicate(timeout=1200)
            usage = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpu = usage.ru_utime + usage.ru_stime - self.cpu_so_far
            self.cpu_so_far = usage.ru_utime + usage.ru_stime
            if proc.returncode != 0 or "error" in err.lower() or "couldn't" in err:
                raise SystemExit("%s failed:\n%s" % (name, err))
            best = cpu if best is None else min(best, cpu)
        return best

    def dsp_time(self, body, name, seconds):
        """CPU time (s) of seconds of audio of body's patch alone: the best run of it less
        the best run of the same patch quitting before its first DSP tick, so pd's start-up
        and the patch's set-up (loading, presets: a plate's modes take ~0.8 s) are out."""
        return (self.run(self.patch(seconds, body), name)
                - self.run(self.patch(0.0, body), name + "-setup"))


def bp_bank(n):
    """A patch body of n vanilla [bp~ f 10] fed by the header's noise~ (the reference):
    centre frequencies spread like a membrane's partials."""
    def body(lines, i):
        for k in range(n):
            lines.append("#X obj %d %d bp~ %g 10;" % (200 + k % 40 * 10, 10 + k // 40, 100 + 5 * k))
            lines.append("#X connect 4 0 %d 0;" % (i + k))
    return body
