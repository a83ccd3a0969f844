#!/usr/bin/env bash
# ictus against its peers, side by side in one run (docs/benchmarks.md):
# the drum in Pd against vanilla [bp~] banks and the Sound Design Toolkit, and
# `ictusd track --mode joint` against MuJoCo's CMU humanoid, plus `ictusd render`.
# Installs the peers it needs into BUILD_DIR/peers/venv, or into $ICTUS_PEERS_VENV
# if set (PyPI: mujoco and dm_control, pysdt), never into the source tree;
# nothing of theirs is committed.
# Usage: bench/peers/run_peers.sh [BUILD_DIR] [bench_peers.py options: --rounds R,
#        --sizes 64,256,1024,4096, --before OLD_BUILD/ictus, --json FILE, --skip ...]
# The build needs the Pd library and ictusd (scripts/build.sh BUILD_DIR).
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
shift || true
for need in "$build/ictus/membrane~.pd_linux" "$build/ictusd"; do
    if [ ! -e "$need" ]; then
        echo "run_peers.sh: no $need; build first (scripts/build.sh $build)" >&2
        exit 1
    fi
done
venv=${ICTUS_PEERS_VENV:-$build/peers/venv}
# The peers' versions: the figures in docs/benchmarks.md were taken with these.
peers=(mujoco==4.0.0 dm_control==1.0.50 pysdt==0.1.2)
have='import importlib.util as u, sys; sys.exit(not all(u.find_spec(m) for m in ("mujoco", "dm_control", "pysdt")))'
if [ ! -x "$venv/bin/python" ] || ! "$venv/bin/python" -c "$have" 2>/dev/null; then
    echo "run_peers.sh: installing ${peers[*]} into $venv" >&2
    /usr/bin/python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet "${peers[@]}"
fi
exec /usr/bin/python3 "$root/bench/peers/bench_peers.py" "$build" --python "$venv/bin/python" "$@"
