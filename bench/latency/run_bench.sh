#!/usr/bin/env bash
# Strike-to-onset latency, OSC -> Pd, real time over loopback: [ictus-receive]
# (timetag-scheduled) against a bare [oscparse] (fires on arrival). Prints a table.
# Usage: bench/latency/run_bench.sh [BUILD_DIR] [--strikes 200] [--runs 3] ...
# Other load on the machine widens the figures: run when quiet, keep the best run.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$root/build}
shift || true
if [ ! -f "$build/ictus/ictus_timetag.pd_linux" ]; then
    echo "run_bench.sh: no $build/ictus/ictus_timetag.pd_linux; build first (scripts/build.sh $build)" >&2
    exit 1
fi
echo "machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cpu; $(pd -version 2>&1 | head -1 | cut -d' ' -f1)"
echo "date: $(date -u '+%Y-%m-%d %H:%M UTC'); load before: $(cut -d' ' -f1-3 /proc/loadavg)"
ICTUS_PD=${ICTUS_PD:-pd} PYTHONPATH="$root/python${PYTHONPATH:+:$PYTHONPATH}" \
    /usr/bin/python3 "$root/bench/latency/bench_latency.py" "$build" "$@"
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
