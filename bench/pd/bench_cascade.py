"""The crash's cascade in real Pd: what membrane~ "preset crash" costs with its energy
cascade (the preset's), without it (cascade 0, the linear plate) and with the von Karman
coupling of its lowest modes instead (cascade 0, vonkarman 1), each with its own
contact~ (a 13.8 g stick, wood tip, 6 m/s at r/a 0.9, every 250 ms, so that the plate
rings throughout), in `pd -batch` at 48 kHz, in one run of the script:

    share of one core = t_crash / S

with t the CPU time (user + sys) of pd for S seconds of audio, best of R runs, less the
best of R runs of the same patch quitting before its first DSP tick (pd's start-up and the
plate's set-up, ~0.8 s: pdbench.Bench.dsp_time), and the ratios to the linear plate.
Usage: bench_cascade.py BUILD_DIR [--runs R] [--seconds S]"""
import shutil

import pdbench

args, bench = pdbench.from_args("ictus-bench-cascade-")
work = bench.work


def crash(setup):
    def body(lines, i):
        lines.append("#X obj 200 10 membrane~ bench-crash;")  # i
        lines.append("#X msg 200 40 preset crash%s;" % setup)  # i+1
        lines.append("#X obj 200 70 contact~ bench-crash;")  # i+2
        lines.append("#X msg 200 100 tip wood \\, mass 0.0138 \\, hit 6 0.9 0;")  # i+3
        lines.append("#X obj 10 200 metro 250;")  # i+4
        lines.append("#X connect 0 0 %d 0;" % (i + 1))
        lines.append("#X connect %d 0 %d 0;" % (i + 1, i))
        lines.append("#X connect %d 0 %d 0;" % (i + 3, i + 2))
        lines.append("#X connect 0 0 %d 0;" % (i + 4))
        lines.append("#X connect %d 0 %d 0;" % (i + 4, i + 3))
    return body


s = args.seconds
lin = bench.dsp_time(crash(" \\, cascade 0"), "linear", s) / s
casc = bench.dsp_time(crash(""), "energy cascade", s) / s
vk = bench.dsp_time(crash(" \\, cascade 0 \\, vonkarman 1"), "von Karman", s) / s
print("crash in Pd, %d Hz, %g s of audio, best of %d runs" % (args.sr, s, args.runs))
print("share of one core: linear plate %.2f %%, with the energy cascade %.2f %% (%.2fx), "
      "with the von Karman coupling %.2f %% (%.2fx)" % (100.0 * lin, 100.0 * casc, casc / lin,
                                                      100.0 * vk, vk / lin))
shutil.rmtree(work, ignore_errors=True)
