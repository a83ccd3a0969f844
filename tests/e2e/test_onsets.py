"""Offline, end to end (docs/osc.md): the real `ictusd render` -> its events.txt ->
patches/ictus-render.pd in the real pd (batch mode) -> WAV, and the onsets
found in the WAV (the signal only, e2e_util.detect_onsets) against the
daemon's strike log strikes.csv: every strike's onset within 1 ms, no extra
onsets. How the strikes are dealt into passes so that each onset is measured on
a drum at rest: e2e_util's doc and docs/main-job.md.

  --source mocap   the CMU clip (data rule: FAIL under CI=true when missing,
                   SKIP otherwise)
  --source score   a score (--score FILE; without it the default score,
                   `ictusd render --out DIR`); skipped with a message while
                   `ictusd render --help` has no --score. CTest uses
                   tests/e2e/short.score (fast alternating hands, bounces; the
                   default score is checked by test_main_job.py).
Also: events.txt and strikes.csv agree (hit times to the microsecond, same
hands and velocities), and the whole events file rendered once with the drum
of render.json is finite, sounds, and is silent before the first strike, whose
onset is on its sample."""
import argparse
import os
import subprocess
import sys

import numpy as np

from ictus_tools import e2e_util as u
from ictus_tools.checks import check
from ictus_tools.pdrun import error_lines, make_workdir

SKIP = 77  # CTest SKIP_RETURN_CODE

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
ap.add_argument("--source", choices=("mocap", "score"), required=True)
ap.add_argument("--score", help="score file for --source score (default: the built-in score)")
args = ap.parse_args()
build = os.path.abspath(args.build)
ictusd = os.path.join(build, "ictusd")
check(os.access(ictusd, os.X_OK), "ictusd is built at %s" % ictusd)
work = make_workdir("ictus-e2e-onsets-")
out = os.path.join(work, "render")

help_text = subprocess.run([ictusd, "render", "--help"], capture_output=True, text=True,
                           timeout=60)
help_text = help_text.stdout + help_text.stderr
if args.source == "mocap":
    data = os.environ.get("ICTUS_DATA_DIR") or os.path.join(u.ROOT, "..", "shared", "data")
    clip = os.path.join(data, "cmu", "80_13.bvh")
    if not os.path.isfile(clip):
        msg = "data file %s is missing (set ICTUS_DATA_DIR to the folder holding cmu/)" % clip
        if os.environ.get("CI") == "true":
            check(False, msg)
        print("SKIPPED:", msg)
        sys.exit(SKIP)
    cmd = [ictusd, "render", "--mocap", clip, "--out", out]
else:
    if "--score" not in help_text:
        print("SKIPPED: `ictusd render --help` has no --score yet: the default score cannot "
              "be rendered (the render verb, docs/perform.md)")
        sys.exit(SKIP)
    cmd = [ictusd, "render", "--out", out]
    if args.score:
        cmd += ["--score", os.path.abspath(args.score)]

proc = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
check(proc.returncode == 0, "%s ran: %s" % (" ".join(cmd[1:]), (proc.stdout + proc.stderr)[-2000:]))
strikes = u.read_strikes(os.path.join(out, "strikes.csv"))
events = u.read_events(os.path.join(out, "events.txt"))
hits = [w for _, w in events if w and w[0] == "hit"]
check(len(strikes) >= 4, "the render has strikes to check (%d)" % len(strikes))
check(len(hits) == len(strikes), "one hit line per strike (%d, %d)" % (len(hits), len(strikes)))
times_us = u.hit_times_us(events)
worst_us = max(abs(t - round(s["time_s"] * 1e6)) for t, s in zip(times_us, strikes))
check(worst_us == 0, "events.txt's running delays are strikes.csv's times to the microsecond "
      "(worst %d us)" % worst_us)
check(all(int(w[1]) == s["hand"] and int(w[3]) == s["bounce"] and
          abs(float(w[4]) - s["normal_velocity_mps"]) < 1e-4 for w, s in zip(hits, strikes)),
      "hit lines carry each strike's hand, bounce flag and normal velocity")

# Strikes whose normal velocity is not towards the membrane (a stick sliding or
# lifting while in contact) are clamped by contact~ with one error line each:
# counted here, not hidden; any other error line fails.
non_approaching = [s for s in strikes if not s["normal_velocity_mps"] > 0]
drum = u.drum_lines(os.path.join(out, "render.json"))


def unexpected_errors(log):
    lines = error_lines(log)
    clamp = [l for l in lines if "contact~: hit: velocity must be in" in l]
    return [l for l in lines if l not in clamp], len(clamp)


# The whole file once, with the drum of render.json.
wav = os.path.join(work, "performance.wav")
seconds = round(strikes[-1]["time_s"] + 1.0, 3)
full_events = os.path.join(work, "full.txt")
u.write_events(full_events, drum, events)
x, sr, log = u.render_pd(build, full_events, wav, seconds)
others, clamped = unexpected_errors(log)
check(not others, "the full render has no error lines: %s" % others)
check(clamped == len(non_approaching),
      "one clamp message per strike with normal velocity <= 0 (%d, %d)" % (clamped,
                                                                           len(non_approaching)))
check(sr == 48000 and x.shape == (int(round(seconds * sr)), 2) and np.all(np.isfinite(x)),
      "performance WAV: 2 channels, 48 kHz, %.3f s, finite" % seconds)
peak = float(np.abs(x).max())
check(peak > 1e-3, "it sounds (peak %.3g)" % peak)
first = u.detect_onsets(x, sr)[0]
want = int(np.floor(strikes[0]["time_s"] * sr + 0.5))
check(first == want, "silent before the first strike, which starts on its sample (%d vs %d)"
      % (first, want))

# Every strike in the full WAV, on the real ringing drum: where the performance
# departs from the performance without that strike and the ones after it.
departures, dlogs = u.departure_onsets(build, events, drum, x, work=work)
dep_ms, dep_failures, dep_notes = u.judge_departures(departures, strikes, sr)
known = [abs(v) for v in dep_ms.values() if v is not None]
print("full WAV, departure onsets - strike time: max %.4f ms, exact %d of %d"
      % (max(known) if known else float("nan"), sum(v == 0 for v in known), len(dep_ms)))
for _, text in dep_notes:
    print("  NOTE:", text)

# Every strike alone on a drum at rest.
result = u.check_onsets(build, events, strikes, work, header=drum)
for p, log in enumerate(result["logs"]):
    others, _ = unexpected_errors(log)
    check(not others, "pass %d has no error lines: %s" % (p, others))
errors = result["errors_ms"]
print("%d strikes (%d bounces, %d with normal velocity <= 0) in %d passes"
      % (len(strikes), sum(s["bounce"] for s in strikes), len(non_approaching),
         len(result["passes"])))
found = [abs(e) for e in errors if e is not None]
if found:
    print("onset - strike time: max %.4f ms, mean %.4f ms, exact (0 samples) %d of %d"
          % (max(found), float(np.mean(found)), sum(e == 0 for e in found), len(found)))
for i, e in enumerate(errors):
    if e is None or e != 0:
        s = strikes[i]
        print("  strike %d (hand %d, bounce %d, %.4f m/s at %.6f s): %s"
              % (i, s["hand"], s["bounce"], s["normal_velocity_mps"], s["time_s"],
                 "no onset" if e is None else "%+.4f ms" % e))
check(not result["missing"], "every strike has an onset within 1 ms (missing: %s)"
      % result["missing"])
check(not result["extra"], "no extra onsets (pass, time s: %s)" % result["extra"])
check(not dep_failures, "in the full WAV every strike starts on time: never early, strokes "
      "within 1 ms (%s)" % "; ".join(t for _, t in dep_failures))
