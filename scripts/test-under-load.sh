#!/usr/bin/env bash
# README's test command with the machine kept busy beside it: stress-ng loads
# every core (--cpu 0) for as long as the tests run, so that waits that are
# not handshakes, and deadlines that are too tight, show up here and not on a
# user's busy machine. Usage: scripts/test-under-load.sh [runs, default 1]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
bash scripts/deps.sh stress-ng
runs=${1:-1}
stress-ng --cpu 0 --cpu-load 100 --quiet &
load=$!
trap 'kill "$load" 2>/dev/null || true; wait "$load" 2>/dev/null || true' EXIT
for ((i = 1; i <= runs; ++i)); do
    echo "== test.sh under load: run $i of $runs (load average: $(cut -d' ' -f1-3 /proc/loadavg)) =="
    bash scripts/test.sh
done
echo "== done under load (load average: $(cut -d' ' -f1-3 /proc/loadavg)) =="
