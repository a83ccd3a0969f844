#!/usr/bin/env bash
# README's test command: installs what is missing, builds, runs every test with CTest,
# then builds and runs the whole suite again under AddressSanitizer + UBSan (where the
# physics-heavy end-to-end tests play fewer seeds: the release run holds the physics; each
# one's CMakeLists.txt says which), then runs each libFuzzer harness briefly (clang).
# A fresh build folder has no CTest timings yet: the long tests' COST (tests/CMakeLists.txt)
# starts them first.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"

bash scripts/deps.sh
jobs=$(nproc 2>/dev/null || echo 2)

echo "== release build and tests (build/) =="
# the Python environment of the corpus tests (build/venv, PyPI; minutes on a clean clone,
# mostly downloads), made while the release build compiles; they skip without it, or fail
# under CI=true
bash scripts/venv.sh "$root/build" >/dev/null &
venv_pid=$!
# Every part is named ON: the main job (scripts/main.sh) configures the same
# build/ folder without tests, and CMake keeps cached options.
parts=(-DICTUS_BUILD_EXTERNALS=ON -DICTUS_BUILD_DAEMON=ON -DICTUS_BUILD_TESTS=ON)
bash scripts/build.sh "$root/build" -DCMAKE_BUILD_TYPE=Release -DICTUS_SANITIZE=OFF "${parts[@]}" \
    -DICTUS_BUILD_BENCH=ON
wait "$venv_pid" || echo "test.sh: no build/venv (scripts/venv.sh failed)" >&2
(cd build && ctest --output-on-failure --no-tests=error -j "$jobs")

echo "== AddressSanitizer + UndefinedBehaviorSanitizer build and tests (build-asan/) =="
bash scripts/build.sh "$root/build-asan" -DCMAKE_BUILD_TYPE=Debug -DICTUS_SANITIZE=ON \
    "${parts[@]}" -DICTUS_BUILD_BENCH=OFF
(cd build-asan && ctest --output-on-failure --no-tests=error -j "$jobs")

echo "== libFuzzer harnesses, a short run each (build-fuzz/, clang) =="
# Only the harnesses and the libraries they fuzz; each CTest run replays its
# seed corpus (fuzz/corpus/) and fuzzes for ICTUS_FUZZ_SECONDS. docs/fuzzing.md.
launcher=()
if command -v ccache >/dev/null; then
    export CCACHE_BASEDIR="$root" CCACHE_NOHASHDIR=true
    launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
CC=clang CXX=clang++ cmake -S "$root" -B "$root/build-fuzz" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DICTUS_BUILD_FUZZ=ON -DICTUS_BUILD_EXTERNALS=OFF -DICTUS_BUILD_TESTS=OFF \
    -DICTUS_BUILD_BENCH=OFF "${launcher[@]}" >/dev/null
cmake --build build-fuzz --target ictus_fuzz -j "$jobs"
(cd build-fuzz && ctest -L fuzz --output-on-failure --no-tests=error -j "$jobs")
