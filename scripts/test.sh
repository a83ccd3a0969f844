#!/usr/bin/env bash
# README's test command: installs what is missing, builds, runs every test with CTest,
# then builds and runs the whole suite again under AddressSanitizer + UBSan.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"

bash scripts/deps.sh
jobs=$(nproc 2>/dev/null || echo 2)

echo "== release build and tests (build/) =="
bash scripts/build.sh "$root/build" -DCMAKE_BUILD_TYPE=Release -DICTUS_SANITIZE=OFF
(cd build && ctest --output-on-failure -j "$jobs")

echo "== AddressSanitizer + UndefinedBehaviorSanitizer build and tests (build-asan/) =="
bash scripts/build.sh "$root/build-asan" -DCMAKE_BUILD_TYPE=Debug -DICTUS_SANITIZE=ON \
    -DICTUS_BUILD_BENCH=OFF
(cd build-asan && ctest --output-on-failure -j "$jobs")
