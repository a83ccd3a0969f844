#!/usr/bin/env bash
# The Python environment of ictus-corpus (docs/corpus.md): BUILD/venv, made with the Debian
# python3 (--system-site-packages: numpy and scipy of scripts/deps.sh stay visible) and the
# pinned packages of python/ictus_corpus/requirements.txt from PyPI. Idempotent: a venv whose
# packages already import is kept. Prints the venv's python on stdout.
# usage: scripts/venv.sh [BUILD_DIR]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
venv=$build/venv
req=$root/python/ictus_corpus/requirements.txt
py=/usr/bin/python3
[[ -x $py ]] || py=$(command -v python3)
if [[ -x $venv/bin/python ]] && cmp -s "$req" "$venv/requirements.txt" &&
    "$venv/bin/python" -c "import dask.distributed, pyarrow, pandas, tqdm" 2>/dev/null; then
    echo "$venv/bin/python"
    exit 0
fi
mkdir -p "$build"
"$py" -m venv --system-site-packages "$venv" >&2
"$venv/bin/python" -m pip install -q -r "$req" >&2
cp "$req" "$venv/requirements.txt"
echo "$venv/bin/python"
