#!/usr/bin/env bash
# The paper's Figure 5 from one command (docs/main-job.md): the virtual percussionist
# plays a score that mixes legato and accent beats of both hands under a tempo
# change (examples/scores/figure5.txt: 80 bpm, then 80 -> 140 bpm), and the
# heights of the right and left stick tips are plotted against time with the
# score above and the strike list marked.
#   usage: scripts/figure5.sh [SCORE] [OUT_DIR]
# SCORE defaults to examples/scores/figure5.txt, OUT_DIR to out/figure5.
# ictusd is taken from $ICTUSD, else build/ictusd (built if missing).
# Writes OUT_DIR/{strikes.csv,events.txt,render.json,tips.csv,notes.csv,...}
# (ictusd render) and OUT_DIR/figure5.png, OUT_DIR/figure5.svg.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
score=${1:-$root/examples/scores/figure5.txt}
out=${2:-$root/out/figure5}
if [[ ! -f $score ]]; then
    echo "figure5.sh: score '$score' not found" >&2
    exit 1
fi
ictusd=${ICTUSD:-$root/build/ictusd}
if [[ ! -x $ictusd ]]; then
    echo "figure5.sh: building ictusd in $root/build" >&2
    cmake -S "$root" -B "$root/build" >/dev/null
    cmake --build "$root/build" --target ictusd -j 2 >/dev/null
fi
if ! "$ictusd" render --help 2>&1 | grep -q -- "--score"; then
    echo "figure5.sh: this ictusd cannot render a score yet (no --score in 'ictusd render --help')" >&2
    exit 1
fi
mkdir -p "$out"
"$ictusd" render --score "$score" --out "$out" --force
PYTHONPATH="$root/python${PYTHONPATH:+:$PYTHONPATH}" /usr/bin/python3 -m ictus_tools.figure5 \
    "$out" --out "$out/figure5" \
    --title "Stick-tip heights, $(basename "$score") (paper, Figure 5)"
