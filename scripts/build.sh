#!/usr/bin/env bash
# Configures and builds ictus into a build folder. Usage: scripts/build.sh [BUILD_DIR] [cmake args...]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
shift || true
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S "$root" -B "$build" "$@" >/dev/null
cmake --build "$build" -j "$jobs"
