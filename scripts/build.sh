#!/usr/bin/env bash
# Configures and builds ictus into a build folder. Usage: scripts/build.sh [BUILD_DIR] [cmake args...]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
shift || true
jobs=$(nproc 2>/dev/null || echo 2)
# ccache (scripts/deps.sh installs it) makes a rebuild of sources already compiled
# on this machine, in this clone or another one, a cache hit: paths are taken
# relative to the clone (CCACHE_BASEDIR), and the build folder is not hashed.
launcher=()
if command -v ccache >/dev/null; then
    export CCACHE_BASEDIR="$root" CCACHE_NOHASHDIR=true
    launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
cmake -S "$root" -B "$build" "${launcher[@]}" "$@" >/dev/null
cmake --build "$build" -j "$jobs"
