"""The README main job (docs/main-job.md)'s core steps on the default score, in this
build (scripts/main.sh --no-deps --no-build: ictusd render --out, pd batch
render, ictus_tools.figure5), and what it leaves in its output folder:
- performance.wav: the events rendered to the sample, peaking at or below
  -0.3 dBFS, its two channels within 3 dB of each other in RMS. The onsets found in the
  signal alone match strikes.csv within 1 ms with no extra onsets (the strikes
  rendered again in passes on a drum at rest, e2e_util / docs/main-job.md), and
  the main WAV itself is finite, sounds, is silent before the first strike and
  starts on its sample;
- tips.png and tips.svg exist and are non-trivial images;
- performance.bvh parses (a BVH reader written here, independent of the
  daemon's): the hierarchy's channel count matches every motion line, Frames
  matches the lines, values finite; and when it carries the sticks
  (LeftHandStick/RightHandStick end sites), forward kinematics here puts their
  tips where tips.csv says the simulated tips were.
Skipped (exit 77) with a message while `ictusd render` has no --score."""
import argparse
import os
import subprocess
import sys

import numpy as np

from ictus_tools import e2e_util as u
from ictus_tools.checks import check
from ictus_tools.pdrun import error_lines, make_workdir, read_wav_float

ap = argparse.ArgumentParser()
ap.add_argument("--build", required=True)
args = ap.parse_args()
build = os.path.abspath(args.build)
ictusd = os.path.join(build, "ictusd")
check(os.access(ictusd, os.X_OK), "ictusd is built at %s" % ictusd)
help_text = subprocess.run([ictusd, "render", "--help"], capture_output=True, text=True,
                           timeout=60)
if "--score" not in help_text.stdout + help_text.stderr:
    print("SKIPPED: `ictusd render --help` has no --score yet: the main job's default score "
          "cannot be rendered (the render verb, docs/perform.md)")
    sys.exit(77)

work = make_workdir("ictus-e2e-main-")
out = os.path.join(work, "out")
env = u.pd_spawning_env(work)
cmd = ["bash", os.path.join(u.ROOT, "scripts", "main.sh"), "--no-deps", "--no-build",
       "--build", build, "--out", out]
proc = subprocess.run(cmd, capture_output=True, text=True, timeout=900, env=env, cwd=work)
print(proc.stdout[-3000:])
check(proc.returncode == 0, "scripts/main.sh --no-deps --no-build ran: %s" % proc.stderr[-3000:])
for name in ("performance.wav", "strikes.csv", "events.txt", "render.json", "tips.png",
             "tips.svg"):
    check(os.path.isfile(os.path.join(out, name)) and os.path.getsize(os.path.join(out, name)) > 0,
          "main job wrote %s" % name)
check(out in proc.stdout and "performance.wav" in proc.stdout,
      "main job printed where its outputs are")

# --- the sound ---------------------------------------------------------------
strikes = u.read_strikes(os.path.join(out, "strikes.csv"))
events = u.read_events(os.path.join(out, "events.txt"))
check(len(strikes) >= 8, "the default score gives strikes (%d)" % len(strikes))
times_us = u.hit_times_us(events)
check(len(times_us) == len(strikes) and
      all(t == round(s["time_s"] * 1e6) for t, s in zip(times_us, strikes)),
      "events.txt holds strikes.csv's times to the microsecond")
x, sr = read_wav_float(os.path.join(out, "performance.wav"))
check(sr == 48000 and x.shape[1] == 2 and np.all(np.isfinite(x)), "performance.wav: 2 ch, 48 kHz, finite")
check(x.shape[0] / sr > strikes[-1]["time_s"], "performance.wav lasts past the last strike")
check(float(np.abs(x).max()) > 1e-3, "performance.wav sounds")
# Listenable: no sample within 0.3 dB of full scale, and a stereo
# mix whose two channels are within 3 dB of each other in RMS.
peak_dbfs = 20 * np.log10(float(np.abs(x).max()))
rms_db = [20 * np.log10(float(np.sqrt(np.mean(x[:, c].astype(np.float64) ** 2)))) for c in (0, 1)]
print("performance.wav: peak %.2f dBFS, RMS %.2f / %.2f dBFS" % (peak_dbfs, rms_db[0], rms_db[1]))
check(peak_dbfs <= -0.3, "performance.wav peaks at or below -0.3 dBFS (%.2f)" % peak_dbfs)
check(abs(rms_db[0] - rms_db[1]) <= 3.0, "performance.wav's channels are within 3 dB in RMS "
      "(%.2f dB apart)" % abs(rms_db[0] - rms_db[1]))
first = u.detect_onsets(x, sr)[0]
want = int(np.floor(strikes[0]["time_s"] * sr + 0.5))
check(first == want, "performance.wav is silent before the first strike, which starts on its "
      "sample (%d vs %d)" % (first, want))
drum = u.drum_lines(os.path.join(out, "render.json"))
result = u.check_onsets(build, events, strikes, work, header=drum)
for p, log in enumerate(result["logs"]):
    others = [l for l in error_lines(log) if "contact~: hit: velocity must be in" not in l]
    check(not others, "onset pass %d has no error lines: %s" % (p, others))
found = [abs(e) for e in result["errors_ms"] if e is not None]
if found:
    print("onset - strike time: max %.4f ms, mean %.4f ms, exact %d of %d, %d passes"
          % (max(found), float(np.mean(found)), sum(e == 0 for e in found), len(found),
             len(result["passes"])))
# and in the main job's own WAV (real drum, set by main.sh through -send): where
# it departs from a render of the strikes before each one, the drum sent as
# ictusd render sends it (e2e_util).
# The sanitizer build (ICTUS_PD_PRELOAD) renders each cut at a fraction of real time and
# looks for memory faults, not timing: there the first strike (a cut of no hits) and the last
# (a cut of every hit but one, the whole score's sound) only; the release build checks every
# strike.
indices = None
if os.environ.get("ICTUS_PD_PRELOAD"):
    indices = sorted({0, len(strikes) - 1})
    print("sanitizer build: departure onsets of strikes %s only" % indices)
departures, _ = u.departure_onsets(build, events, drum, x, work=work, header_sent=True,
                                   indices=indices)
dep, dep_failures, dep_notes = u.judge_departures(departures, strikes, sr)
known = [abs(v) for v in dep.values() if v is not None]
print("performance.wav, departure onsets - strike time: max %.4f ms, exact %d of %d"
      % (max(known) if known else float("nan"), sum(v == 0 for v in known), len(dep)))
for _, text in dep_notes:
    print("  NOTE:", text)
check(not result["missing"], "every strike has an onset within 1 ms (missing %s)" % result["missing"])
check(not result["extra"], "no extra onsets (%s)" % result["extra"])
check(not dep_failures, "in performance.wav every strike starts on time: never early, strokes "
      "within 1 ms (%s)" % "; ".join(t for _, t in dep_failures))

# --- the plot ------------------------------------------------------------------
with open(os.path.join(out, "tips.png"), "rb") as f:
    png = f.read()
check(png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 20000, "tips.png is a PNG (%d bytes)" % len(png))
with open(os.path.join(out, "tips.svg")) as f:
    svg = f.read()
check("<svg" in svg and svg.count("<path") > 10, "tips.svg is an SVG with drawn paths")


# --- the BVH ---------------------------------------------------------------------
def parse_bvh(path):
    """-> joints [(name, parent, offset, channels, end_site)], frame_time, frames [n, k]."""
    with open(path) as f:
        tokens_lines = f.read().splitlines()
    i = 0
    joints, stack = [], []

    def toks(k):
        return tokens_lines[k].split()

    check(tokens_lines[0].strip() == "HIERARCHY", "BVH starts with HIERARCHY")
    i = 1
    pending = None
    while True:
        t = toks(i)
        if not t:
            i += 1
            continue
        if t[0] in ("ROOT", "JOINT"):
            pending = (" ".join(t[1:]), False)
        elif t[0] == "End":
            pending = ((joints[stack[-1]][0] if stack else "?") + "_End", True)
        elif t[0] == "{":
            joints.append([pending[0], stack[-1] if stack else -1, None, [], pending[1]])
            stack.append(len(joints) - 1)
        elif t[0] == "OFFSET":
            joints[stack[-1]][2] = np.array([float(v) for v in t[1:4]])
        elif t[0] == "CHANNELS":
            if int(t[1]) != len(t) - 2:
                check(False, "BVH line %d: CHANNELS count matches the names" % (i + 1))
            joints[stack[-1]][3] = t[2:]
        elif t[0] == "}":
            stack.pop()
        elif t[0] == "MOTION":
            break
        else:
            check(False, "BVH line %d: unexpected '%s'" % (i + 1, t[0]))
        i += 1
    check(not stack, "BVH hierarchy braces balance")
    n_frames = int(toks(i + 1)[1])
    frame_time = float(toks(i + 2)[2])
    rows = [l.split() for l in tokens_lines[i + 3:] if l.strip()]
    width = sum(len(j[3]) for j in joints)
    check(len(rows) == n_frames, "BVH has Frames: %d motion lines (%d)" % (n_frames, len(rows)))
    check(all(len(r) == width for r in rows), "every BVH motion line has %d values" % width)
    data = np.array(rows, dtype=float) if rows else np.zeros((0, width))
    check(np.all(np.isfinite(data)), "BVH values are finite")
    return joints, frame_time, data


def axis_matrices(axis, deg):
    """The rotations about `axis` by each angle of `deg` (degrees), [n, 3, 3]."""
    a = np.radians(np.asarray(deg, dtype=float))
    c, s, one, zero = np.cos(a), np.sin(a), np.ones_like(a), np.zeros_like(a)
    if axis == "X":
        m = [[one, zero, zero], [zero, c, -s], [zero, s, c]]
    elif axis == "Y":
        m = [[c, zero, s], [zero, one, zero], [-s, zero, c]]
    else:
        m = [[c, -s, zero], [s, c, zero], [zero, zero, one]]
    return np.moveaxis(np.array(m), (0, 1), (-2, -1))


def fk(joints, rows):
    """World positions (file units) of every joint for each motion line of `rows` [n, k]
    (one line per frame, solved together): [joint] -> [n, 3]. R = product of the rotation
    channels in file order (intrinsic)."""
    n = len(rows)
    pos, rot, k = [None] * len(joints), [None] * len(joints), 0
    for j, (name, parent, offset, channels, end) in enumerate(joints):
        moved, r = np.zeros((n, 3)), np.broadcast_to(np.eye(3), (n, 3, 3))
        for c in channels:
            v = rows[:, k]
            k += 1
            if c.endswith("position"):
                moved[:, "XYZ".index(c[0])] = v
            else:
                r = r @ axis_matrices(c[0], v)
        if parent < 0:
            pos[j], rot[j] = offset + moved, r
        else:
            pos[j] = pos[parent] + np.einsum("nij,j->ni", rot[parent], offset)
            rot[j] = rot[parent] @ r
    return pos


bvh_path = os.path.join(out, "performance.bvh")
check(os.path.isfile(bvh_path) and os.path.getsize(bvh_path) > 0, "main job wrote performance.bvh")
joints, frame_time, data = parse_bvh(bvh_path)
print("performance.bvh: %d joints, %d frames at %.6g s" % (len(joints), len(data), frame_time))
check(len(joints) >= 20 and len(data) > 0 and 0 < frame_time < 1, "the BVH has a skeleton and frames")
names = [j[0] for j in joints]
tips_csv = os.path.join(out, "tips.csv")
if "LeftHandStick_End" in names and "RightHandStick_End" in names and os.path.isfile(tips_csv):
    # The exported sticks against the simulated tips: at every BVH frame whose
    # time is a tips.csv sample, the tip heights agree to the export's
    # exactness (1e-6 m, tests/mocap/test_bvh_writer.cpp), tips.csv's last
    # digit (1e-5 m) and the drift of the physics' ball joints, which an
    # exported pose (rotations on fixed offsets) cannot show: measured over
    # the default score every 4 ms (FK of pose_from_frames vs the physics'
    # hand frames), median 0.05 mm, p99 0.4 mm, max 0.80 mm (at an impact).
    from ictus_tools import figure5  # (its column matcher)
    with open(tips_csv) as f:
        lines = [l.strip() for l in f if l.strip() and not l.startswith("#")]
    header = lines[0].split(",")
    cols = figure5.tip_columns(header)
    table = np.array([[float(v) for v in l.split(",")] for l in lines[1:]])
    t = table[:, header.index("time_s")]
    # The tips.csv sample of each BVH frame: k - 1 or k (searchsorted), the first within 1 us.
    frame_t = np.arange(len(data)) * frame_time
    k = np.searchsorted(t, frame_t)
    sample = np.full(len(data), -1)
    for kk in (k - 1, k):
        inside = (kk >= 0) & (kk < len(t))
        near = np.abs(t[np.clip(kk, 0, len(t) - 1)] - frame_t) < 1e-6
        take = (sample < 0) & inside & near
        sample[take] = kk[take]
    frames = np.flatnonzero(sample >= 0)
    poses = fk(joints, data[frames])  # the frames' joints, solved once for both hands
    worst = {}
    for hand, end in (("left", "LeftHandStick_End"), ("right", "RightHandStick_End")):
        errs = np.abs(poses[names.index(end)][:, 1] - table[sample[frames], cols[(hand, "sim")]])
        worst[hand] = (float(errs.max()) if len(errs) else None, len(errs))
    print("BVH stick tips vs tips.csv (sim y): %s" % worst)
    check(all(n > 0 for _, n in worst.values()), "BVH frames fall on tips.csv samples")
    check(all(e < 1e-3 for e, _ in worst.values()),
          "BVH stick-tip heights match tips.csv within 1 mm: %s" % worst)
else:
    print("NOTE: performance.bvh has no stick end sites or there is no tips.csv: "
          "tips not compared")
