#!/usr/bin/env bash
# The paper's Figure 4 from one command: joint-space (ID) vs Cartesian (IK + ID)
# tracking of the same motion with the same PD gains and limits.
#   usage: scripts/figure4.sh [MOCAP.bvh] [OUT_DIR]
# MOCAP defaults to the CMU drumming clip under $ICTUS_DATA_DIR (default
# ../shared/data next to the repo); OUT_DIR to out/figure4. ictusd is taken
# from $ICTUSD, else build/ictusd (built if missing).
# Writes OUT_DIR/{joint,cartesian}/{track.csv,summary.json}, figure4.png,
# figure4.svg and figure4.md (table of RMS errors and the options used).
# FIGURE4_OPTS: extra ictusd track options for both runs (default none).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
data=${ICTUS_DATA_DIR:-$root/../shared/data}
mocap=${1:-$data/cmu/80_13.bvh}
out=${2:-$root/out/figure4}
if [[ ! -f $mocap ]]; then
    echo "figure4.sh: motion file '$mocap' not found (give one, or set ICTUS_DATA_DIR)" >&2
    exit 1
fi
ictusd=${ICTUSD:-$root/build/ictusd}
if [[ ! -x $ictusd ]]; then
    echo "figure4.sh: building ictusd in $root/build" >&2
    cmake -S "$root" -B "$root/build" >/dev/null
    cmake --build "$root/build" --target ictusd -j 2 >/dev/null
fi
# Same options for both modes: the defaults (limits at k = 3, eq. 1's gains,
# Algorithm 2 from the simulated state with the posture task; docs/ik.md).
# Extra options for both runs: FIGURE4_OPTS="--limit-k 4" scripts/figure4.sh
read -r -a extra <<<"${FIGURE4_OPTS:-}"
common=(--mocap "$mocap" --quiet "${extra[@]}")
"$ictusd" track --mode joint "${common[@]}" --out "$out/joint"
"$ictusd" track --mode cartesian "${common[@]}" --out "$out/cartesian"
FIGURE4_OPTS="${FIGURE4_OPTS:-}" /usr/bin/python3 "$root/scripts/figure4.py" "$out"
