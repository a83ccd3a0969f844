#!/usr/bin/env bash
# Benchmarks membrane~ (free and with a contact~) against a bank of vanilla bp~
# in real Pd batch mode and prints a table (ns per mode per sample).
# Usage: bench/pd/run_bench.sh [BUILD_DIR] [--runs R] [--sizes 16,256,...]
# The externals must be built (scripts/build.sh BUILD_DIR). Other load on the
# machine inflates the figures: run when quiet, keep the best of several runs.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$root/build}
shift || true
if [ ! -f "$build/ictus/membrane~.pd_linux" ]; then
    echo "run_bench.sh: no $build/ictus/membrane~.pd_linux; build first (scripts/build.sh $build)" >&2
    exit 1
fi
echo "machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cpu; $(pd -version 2>&1 | head -1 | cut -d' ' -f1)"
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
/usr/bin/python3 "$root/bench/pd/bench_pd.py" "$build" "$@"
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
