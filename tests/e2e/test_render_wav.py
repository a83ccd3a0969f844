"""`ictusd render --wav FILE`: one command from a score to a WAV (docs/main-job.md).
The real ictusd runs the real pd (found on PATH) on its own events.txt, and the
WAV must be bit for bit the one this test gets by running pd itself on that
events file with patches/ictus-render.pd and the drum of render.json (the way
scripts/main.sh used to and tests/e2e do), for the defaults and for
--wav-mix pickups --wav-bits 16 --wav-rate 44100. Also: progress lines while the
physics runs (--progress-every), a clear error before any physics when pd is
not on PATH, and errors naming the file when Pd cannot write it or cannot take
its path. The score is tests/e2e/short.score."""
import argparse
import os
import re
import subprocess

import numpy as np

from ictus_tools import e2e_util as u
from ictus_tools.checks import check
from ictus_tools.pdrun import PD_BATCH, PD_ENV, make_workdir, read_wav_any

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
ap.add_argument("--score", required=True)
args = ap.parse_args()
build = os.path.abspath(args.build)
ictusd = os.path.join(build, "ictusd")
work = make_workdir("ictus-render-wav-")
env = u.pd_spawning_env(work)

def render(out, *extra, environ=None):
    cmd = [ictusd, "render", "--score", args.score, "--out", out, "--bvh-rate", "0",
           "--tips-rate", "0"] + list(extra)
    return subprocess.run(cmd, capture_output=True, text=True, timeout=900, env=environ or env)


def pd_itself(out, wav, sr, *sends, read=True):
    """pd run by the test on render's events.txt: the reference."""
    with open(os.path.join(out, "render.json")) as f:
        import json
        seconds = float(json.load(f)["duration_s"]) + 1.5
    cmd = PD_BATCH + ["-r", str(sr), "-path", os.path.join(build, "ictus"), "-open", u.RENDER_PATCH]
    for s in u.drum_lines(os.path.join(out, "render.json")) + list(sends):
        cmd += ["-send", s]
    cmd += ["-send", "render-file " + os.path.join(out, "events.txt"), "-send", "render-out " + wav,
            "-send", "render-seconds %.3f" % seconds]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=300, env=PD_ENV)
    check(proc.returncode == 0, "pd rendered the reference: %s" % proc.stderr[-1000:])
    return read_wav_any(wav) if read else None


# --- the default WAV, with progress lines --------------------------------------
out = os.path.join(work, "a")
wav = os.path.join(out, "performance.wav")
proc = render(out, "--wav", wav, "--progress-every", "0.001")
print(proc.stdout[-2000:])
check(proc.returncode == 0, "ictusd render --wav ran: %s" % proc.stderr[-2000:])
check(("wrote %s" % wav) in proc.stdout and "peak" in proc.stdout, "it says where the WAV is and its peak")
progress = [float(m.group(1)) for m in re.finditer(r"^render: ([0-9.]+) of [0-9.]+ s simulated",
                                                    proc.stderr, re.M)]
check(len(progress) >= 2 and progress == sorted(progress),
      "progress lines while the physics runs, in order (%d)" % len(progress))
x, sr, bits, is_float = read_wav_any(wav)
check(sr == 48000 and bits == 32 and is_float and x.shape[1] == 2, "a 2-channel 48 kHz float WAV")
strikes = u.read_strikes(os.path.join(out, "strikes.csv"))
check(len(strikes) > 0 and x.shape[0] / sr > strikes[-1]["time_s"] + 1.0,
      "the WAV lasts past the last strike (%.2f s)" % (x.shape[0] / sr))
ref, _, _, _ = pd_itself(out, os.path.join(work, "ref-a.wav"), 48000)
check(ref.shape == x.shape and np.array_equal(ref, x), "the WAV is pd's render of events.txt, bit for bit")
check(os.path.isfile(os.path.join(out, "pd.log")), "pd's output is in pd.log")

# --- another mix, format and rate ---------------------------------------------------
out = os.path.join(work, "b")
wav = os.path.join(out, "p16.wav")
proc = render(out, "--wav", wav, "--wav-mix", "pickups", "--wav-bits", "16", "--wav-rate", "44100",
              "--progress-every", "0")
check(proc.returncode == 0 and "render: " not in proc.stderr,
      "--wav-mix pickups --wav-bits 16 --wav-rate 44100, no progress lines: %s" % proc.stderr[-1000:])
x, sr, bits, is_float = read_wav_any(wav)
ref, rsr, rbits, _ = pd_itself(out, os.path.join(work, "ref-b.wav"), 44100, "render-mix pickups",
                               "render-bits 16")
check(sr == 44100 and bits == 16 and not is_float and rsr == sr and rbits == bits and
      np.array_equal(ref, x), "16-bit 44.1 kHz raw pickups, bit for bit pd's render")

# --- the suffix's case ------------------------------------------------------------------
# Pd writes a name ending in .wav or .WAV as given and adds .wav to any other (".Wav" too):
# --wav TAKE.WAV was refused ("does not end in .wav"). Taken now, written under that name;
# a mixed case, for which pd itself (run here) writes NAME.Wav.wav, refused before any output.
import random
rng = random.Random(20261202)
out = os.path.join(work, "e")
wav = os.path.join(out, "TAKE.WAV")
proc = render(out, "--wav", wav, "--progress-every", "0")
check(proc.returncode == 0 and os.path.isfile(wav) and not os.path.exists(wav + ".wav") and
      read_wav_any(wav)[0].shape[0] > 0, "--wav TAKE.WAV: written under that name (%s)"
      % proc.stderr.strip()[-300:])
mixed = "".join(rng.choice((c.lower(), c.upper())) for c in "wav")
while mixed in ("wav", "WAV"):
    mixed = "".join(rng.choice((c.lower(), c.upper())) for c in "wav")
pd_itself(out, os.path.join(work, "ref-e." + mixed), 48000, read=False)
check(os.path.isfile(os.path.join(work, "ref-e.%s.wav" % mixed)),
      "pd itself writes NAME.%s as NAME.%s.wav" % (mixed, mixed))
bad = os.path.join(work, "f", "take." + mixed)
proc = render(os.path.join(work, "f"), "--wav", bad)
check(proc.returncode == 1 and bad in proc.stderr and "adds .wav" in proc.stderr and
      not os.path.exists(os.path.join(work, "f")),
      "--wav take.%s: exit 1 naming it, before any output (%s)" % (mixed, proc.stderr.strip()[-300:]))

# --- errors ----------------------------------------------------------------------------
no_pd = dict(env)
no_pd["PATH"] = os.path.join(work, "empty-path")
out = os.path.join(work, "c")
proc = render(out, "--wav", os.path.join(out, "x.wav"), environ=no_pd)
check(proc.returncode == 1 and "no 'pd' on PATH" in proc.stderr and not os.path.exists(out),
      "no pd on PATH: exit 1 with the reason, before any output (%d: %s)"
      % (proc.returncode, proc.stderr.strip()))
out = os.path.join(work, "d")
bad = os.path.join(work, "no such folder", "x.wav")
proc = render(out, "--wav", bad)
check(proc.returncode == 1 and "x.wav" in proc.stderr and "Pd's messages" in proc.stderr and
      not os.path.exists(out), "a WAV path with a space: exit 1 naming it, before any output (%s)"
      % proc.stderr.strip()[-300:])
bad = os.path.join(work, "missing-folder", "x.wav")
proc = render(out, "--wav", bad)
check(proc.returncode == 1 and "no folder '%s'" % os.path.dirname(bad) in proc.stderr and
      not os.path.exists(out), "a WAV in a folder that does not exist: exit 1 naming it, before "
      "any output (%s)" % proc.stderr.strip()[-300:])
# A folder where no file can be made, even by root: pd fails to write the WAV.
bad = "/proc/ictus-render-wav-%d.wav" % os.getpid()
proc = render(out, "--force", "--wav", bad)
check(proc.returncode == 1 and bad in proc.stderr and "pd.log" in proc.stderr,
      "a WAV pd cannot write: exit 1 naming it and the log (%s)" % proc.stderr.strip()[-400:])
print("PASS")
