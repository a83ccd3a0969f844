#!/usr/bin/env bash
# The main job: the whole chain, headless (docs/main-job.md).
#   1. installs the missing Debian packages (scripts/deps.sh)
#   2. builds the Pd externals and ictusd (no tests, no benchmarks)
#   3. ictusd render: the virtual percussionist plays the default score (the
#      paper's Figure 5: legato and accent beats under a tempo change) with the
#      built-in gesture database, offline: OUT/strikes.csv, OUT/events.txt,
#      OUT/render.json, OUT/tips.csv, OUT/notes.csv, OUT/performance.bvh,
#      OUT/performance.mid
#   4. Pd in batch mode plays the events on the drum of render.json
#      (ictusd render --wav, patches/ictus-render.pd): OUT/performance.wav
#      (stereo, 48 kHz, 32-bit float, peaks below -0.5 dBFS: docs/main-job.md)
#   5. the tip-trajectory plot (ictus_tools.figure5): OUT/tips.png and .svg
# and prints where each output is and a short summary.
#
# usage: scripts/main.sh [--build DIR] [--out DIR] [--score FILE] [--no-deps] [--no-build]
#                        [--mix stereo|pickups] [--bits 16|24|32] [--gain DB]
#                        [--drum-preset NAME]
#        scripts/main.sh [BUILD_DIR]            (as before: the build folder)
#   --build DIR   build folder (default build/)
#   --out DIR     output folder (default out/)
#   --score FILE  play this score instead of the default one (examples/scores/)
#   --no-deps     do not run scripts/deps.sh
#   --no-build    use the existing build in --build as it is
#   --mix M       stereo (default: the drum in the middle, the hands panned) or
#                 pickups (the membrane's two raw pickups)
#   --bits N      16 or 24 (integer PCM) or 32 (float, the default)
#   --gain DB     output gain before the soft limiter (default 0)
#   --drum-preset NAME  the drum (ictusd render --drum-preset; docs/sound.md): paper,
#                 snare, tom, floor-tom, timpani, frame, kick (default snare, wires on)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$root/build
out=$root/out
score=
deps=1
do_build=1
mix=stereo
bits=32
gain=0
drum_preset=snare
while [[ $# -gt 0 ]]; do
    case $1 in
    --build) build=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --score) score=$2; shift 2 ;;
    --no-deps) deps=0; shift ;;
    --no-build) do_build=0; shift ;;
    --mix) mix=$2; shift 2 ;;
    --bits) bits=$2; shift 2 ;;
    --gain) gain=$2; shift 2 ;;
    --drum-preset) drum_preset=$2; shift 2 ;;
    -h | --help) sed -n '2,32p' "$0"; exit 0 ;;
    -*) echo "main.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
    *) build=$1; shift ;;
    esac
done
case $mix in stereo | pickups) ;; *) echo "main.sh: --mix must be stereo or pickups, got '$mix'" >&2; exit 2 ;; esac
case $bits in 16 | 24 | 32) ;; *) echo "main.sh: --bits must be 16, 24 or 32, got '$bits'" >&2; exit 2 ;; esac
if ! [[ $gain =~ ^-?[0-9]+([.][0-9]+)?$ ]]; then
    echo "main.sh: --gain must be a number of dB, got '$gain'" >&2
    exit 2
fi
mkdir -p "$out"
build=$(cd "$(dirname "$build")" && pwd)/$(basename "$build")
out=$(cd "$out" && pwd)
cd "$root"
# the Python helpers' package (docs/python.md)
export PYTHONPATH="$root/python${PYTHONPATH:+:$PYTHONPATH}"

if [[ $deps == 1 ]]; then
    bash scripts/deps.sh
fi
if [[ $do_build == 1 ]]; then
    bash scripts/build.sh "$build" -DICTUS_BUILD_TESTS=OFF -DICTUS_BUILD_BENCH=OFF \
        -DICTUS_BUILD_EXTERNALS=ON -DICTUS_BUILD_DAEMON=ON
fi
ictusd=$build/ictusd
if [[ ! -x $ictusd || ! -d $build/ictus ]]; then
    echo "main.sh: no ictusd or Pd library in $build (run without --no-build)" >&2
    exit 1
fi
# (the whole help read first: grep -q would stop reading early, and with
# pipefail ictusd's SIGPIPE would fail the check)
render_help=$("$ictusd" render --help 2>&1 || true)
if [[ $render_help != *"--wav FILE"* ]]; then
    echo "main.sh: this ictusd cannot render a WAV (no --wav in 'ictusd render --help')" >&2
    exit 1
fi

# 3. the performance, offline and deterministic
rm -f "$out"/{strikes.csv,events.txt,render.json,tips.csv,notes.csv,performance.bvh,performance.mid} \
    "$out"/{performance.wav,tips.png,tips.svg,pd.log}
# 4. the sound, by the same command: the events on the drum the physics used
# (radius, tension, density of render.json), rendered to the sample by pd in
# batch mode (patches/ictus-render.pd; pd's output in OUT/pd.log)
wav=$out/performance.wav
render=("$ictusd" render --out "$out" --force --wav "$wav" --wav-mix "$mix" --wav-bits "$bits"
        --wav-gain "$gain" --drum-preset "$drum_preset")
[[ -n $score ]] && render+=(--score "$score")
status=0
"${render[@]}" || status=$?
if ((status == 3)); then # the files and the WAV are written; ictusd said what diverged
    echo "main.sh: the simulation diverged (ictusd render exit 3): $out holds what was played" >&2
    exit 1
elif ((status != 0)); then
    [[ -f $out/pd.log ]] && cat "$out/pd.log" >&2
    echo "main.sh: ictusd render --wav failed" >&2
    exit 1
fi
for f in strikes.csv events.txt render.json performance.wav; do
    [[ -s $out/$f ]] || { echo "main.sh: ictusd render did not write $out/$f" >&2; exit 1; }
done

# 5. the figure
/usr/bin/python3 -m ictus_tools.figure5 "$out" --out "$out/tips"

# where everything is, and a summary
ICTUS_MIX=$mix /usr/bin/python3 - "$out" <<'PY'
import json, os, sys
import numpy as np
from ictus_tools.pdrun import read_wav_any

out = sys.argv[1]
wav = os.path.join(out, "performance.wav")
x, sr, bits, is_float = read_wav_any(wav)
if x.shape[0] == 0 or not np.all(np.isfinite(x)):
    sys.exit("main.sh: %s is empty or not finite" % wav)
peak = float(np.max(np.abs(x)))
if peak < 1e-3:
    sys.exit("main.sh: %s is silent (peak %g)" % (wav, peak))
rms_db = [20 * np.log10(max(float(np.sqrt(np.mean(x[:, c] ** 2))), 1e-12)) for c in range(x.shape[1])]
limiter = ""
with open(os.path.join(out, "pd.log")) as f:
    for line in f:
        if line.startswith("ictus-render: peak_in_dbfs"):
            w = line.split()
            limiter = ", %s dBFS before the limiter (gain %s dB)" % (w[2], w[6])
meta = json.load(open(os.path.join(out, "render.json")))
bvh = os.path.join(out, "performance.bvh")
frames = joints = None
if os.path.isfile(bvh):
    with open(bvh) as f:
        text = f.read()
    joints = text.count("JOINT ") + text.count("ROOT ")
    for line in text.splitlines():
        if line.startswith("Frames:"):
            frames = int(line.split()[1])
print()
print("main job: outputs in %s" % out)
for name, what in (("performance.wav", "%d channels (%s), %.2f s at %d Hz, %d-bit %s, peak %.2f dBFS%s, "
                    "RMS %s dBFS" % (x.shape[1], os.environ.get("ICTUS_MIX", "?"), x.shape[0] / sr, sr, bits,
                                     "float" if is_float else "PCM", 20 * np.log10(peak), limiter,
                                     " / ".join("%.1f" % r for r in rms_db))),
                   ("strikes.csv", "%s strikes, %s bounces" % (meta.get("strikes"), meta.get("bounces"))),
                   ("events.txt", "the strikes for Pd (qlist)"),
                   ("performance.mid", "the strikes as MIDI notes, channel %s (docs/midi.md)"
                    % meta.get("midi", {}).get("channel", "?")
                    if os.path.isfile(os.path.join(out, "performance.mid")) else "MISSING"),
                   ("tips.png", "stick-tip heights, score and strikes (and tips.svg)"),
                   ("performance.bvh", "%s joints, %s frames" % (joints, frames)
                    if frames is not None else "MISSING"),
                   ("render.json", "drum, duration %.2f s" % float(meta.get("duration_s", 0)))):
    print("  %-16s %s" % (name, what))
PY
