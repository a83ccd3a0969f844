#!/usr/bin/env bash
# ictus-corpus from the repository (docs/corpus.md): installs the missing Debian packages
# (scripts/deps.sh), builds ictusd and the Pd library as scripts/main.sh does, makes the
# Python environment (scripts/venv.sh: build/venv with Dask from PyPI), then runs
# `python -m ictus_corpus ARGS`.
# usage: scripts/corpus.sh [--build DIR] [--no-deps] [--no-build] ICTUS_CORPUS_ARGS...
#   e.g. scripts/corpus.sh --count 200 --seed 1 --out corpus
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$root/build
deps=1
do_build=1
args=()
while [[ $# -gt 0 ]]; do
    case $1 in
    --build) build=$2; shift 2 ;;
    --no-deps) deps=0; shift ;;
    --no-build) do_build=0; shift ;;
    -h | --help) sed -n '2,7p' "$0"; args+=("--help"); shift ;;
    *) args+=("$1"); shift ;;
    esac
done
cd "$root"
if [[ $deps == 1 ]]; then
    bash scripts/deps.sh
fi
if [[ $do_build == 1 ]]; then
    bash scripts/build.sh "$build" -DICTUS_BUILD_TESTS=OFF -DICTUS_BUILD_BENCH=OFF \
        -DICTUS_BUILD_EXTERNALS=ON -DICTUS_BUILD_DAEMON=ON
fi
if [[ ! -x $build/ictusd || ! -d $build/ictus ]]; then
    echo "corpus.sh: no ictusd or Pd library in $build (run without --no-build)" >&2
    exit 1
fi
python=$(bash scripts/venv.sh "$build")
export PYTHONPATH="$root/python${PYTHONPATH:+:$PYTHONPATH}"
exec "$python" -m ictus_corpus --ictusd "$build/ictusd" "${args[@]}"
