#!/usr/bin/env bash
# The demo: installs what is missing, builds (externals and daemon; no tests or
# benchmarks), renders patches/demo/demo.pd (two contact~ sticks and a few ideal
# strikes on one membrane~, 4 s) through the real pd in batch mode into
# out/demo.wav (32-bit float, stereo, 48 kHz), and checks it is finite and not silent.
# Usage: scripts/main.sh [BUILD_DIR]   (default: build/)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
cd "$root"

bash scripts/deps.sh
bash scripts/build.sh "$build" -DICTUS_BUILD_TESTS=OFF -DICTUS_BUILD_BENCH=OFF \
    -DICTUS_BUILD_DAEMON=ON

mkdir -p "$root/out"
wav="$root/out/demo.wav"
rm -f "$wav"
log="$root/out/demo.log"
# -send after -open: the patch takes the output path from [r demo-out] when it writes.
pd -nogui -nosound -batch -stderr -r 48000 -path "$build/ictus" \
    -open "$root/patches/demo/demo.pd" -send "demo-out symbol $wav" >"$log" 2>&1 || {
    cat "$log" >&2
    echo "main.sh: pd failed" >&2
    exit 1
}
if grep -Eiq "error|couldn't" "$log"; then
    cat "$log" >&2
    echo "main.sh: pd reported errors while rendering" >&2
    exit 1
fi

/usr/bin/python3 - "$wav" <<'PY'
import sys
sys.path.insert(0, "tests/pd")
import numpy as np
from pdrun import read_wav_float

x, sr = read_wav_float(sys.argv[1])
seconds = x.shape[0] / sr
peak = float(np.max(np.abs(x))) if x.size else 0.0
rms = float(np.sqrt(np.mean(x.astype(np.float64) ** 2))) if x.size else 0.0
if x.shape[0] == 0 or not np.all(np.isfinite(x)):
    sys.exit("main.sh: %s is empty or not finite" % sys.argv[1])
if peak < 1e-3:
    sys.exit("main.sh: %s is silent (peak %g)" % (sys.argv[1], peak))
print("demo: %d channels, %.2f s at %d Hz, peak %.3f, rms %.4f" % (x.shape[1], seconds, sr, peak, rms))
PY
echo "wrote $wav"
