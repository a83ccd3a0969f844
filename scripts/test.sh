#!/usr/bin/env bash
# README's test command: installs what is missing, builds, runs every test with CTest,
# then builds and runs the whole suite again under AddressSanitizer + UBSan (where the
# physics-heavy end-to-end tests play fewer seeds: the release run holds the physics; each
# one's CMakeLists.txt says which), then runs each libFuzzer harness briefly (clang).
# A fresh build folder has no CTest timings yet: the long tests' COST (tests/CMakeLists.txt)
# starts them first.
#
# Time: the release suite keeps the cores about three quarters busy (its live, UI and network
# tests wait on the real-time clock), so CTest runs one test more than there are cores, and
# the next stage's build compiles beside each suite at the lowest priority (nice 19: it takes
# the idle cycles, the tests keep theirs; the suite passes with every core loaded, README).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"

# Each stage's start is printed with the seconds since this script began (bash's SECONDS).
stage() { echo "== $1 (at ${SECONDS} s) =="; }

bash scripts/deps.sh
jobs=$(nproc 2>/dev/null || echo 2)
test_jobs=$((jobs + 1))

# A build started beside a suite: its pid and log, waited for (and shown when it failed)
# before its own suite starts; killed if this script stops first.
bg_pid=""
bg_log=""
trap '[ -z "$bg_pid" ] || kill -- -"$bg_pid" 2>/dev/null || true' EXIT
start_beside() { # LOG COMMAND...: runs COMMAND at nice 19 in its own process group
    bg_log=$1
    shift
    set -m
    nice -n 19 "$@" >"$bg_log" 2>&1 &
    bg_pid=$!
    set +m
}
wait_beside() { # NAME: waits for the build started beside the last suite
    # Its suite has ended: from now on nothing waits on it, so it builds at normal priority
    # (at nice 19 on a machine whose cores something else keeps busy it stalled for more
    # than 15 minutes). Raising a priority needs root (CAP_SYS_NICE); others keep nice 19.
    renice 0 -g "$bg_pid" >/dev/null 2>&1 || true # absolute (busybox reads -n as a step)
    if ! wait "$bg_pid"; then
        cat "$bg_log" >&2
        echo "test.sh: the $1 build failed (its log above: $bg_log)" >&2
        exit 1
    fi
    bg_pid=""
    tail -n 1 "$bg_log"
}

stage "release build and tests (build/)"
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
mkdir -p build-asan
start_beside build-asan/test-sh-build.log bash scripts/build.sh "$root/build-asan" \
    -DCMAKE_BUILD_TYPE=Debug -DICTUS_SANITIZE=ON "${parts[@]}" -DICTUS_BUILD_BENCH=OFF
echo "test.sh: release build done at ${SECONDS} s"
(cd build && ctest --output-on-failure --no-tests=error -j "$test_jobs")

stage "AddressSanitizer + UndefinedBehaviorSanitizer build and tests (build-asan/)"
wait_beside AddressSanitizer
echo "test.sh: AddressSanitizer build done at ${SECONDS} s"
# The libFuzzer harnesses (clang): only they and the libraries they fuzz; each CTest run
# replays its seed corpus (fuzz/corpus/) and fuzzes for ICTUS_FUZZ_SECONDS. docs/fuzzing.md.
launcher=()
if command -v ccache >/dev/null; then
    export CCACHE_BASEDIR="$root" CCACHE_NOHASHDIR=true
    launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
CC=clang CXX=clang++ cmake -S "$root" -B "$root/build-fuzz" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DICTUS_BUILD_FUZZ=ON -DICTUS_BUILD_EXTERNALS=OFF -DICTUS_BUILD_TESTS=OFF \
    -DICTUS_BUILD_BENCH=OFF "${launcher[@]}" >/dev/null
start_beside build-fuzz/test-sh-build.log cmake --build build-fuzz --target ictus_fuzz -j "$jobs"
(cd build-asan && ctest --output-on-failure --no-tests=error -j "$test_jobs")

stage "libFuzzer harnesses, a short run each (build-fuzz/, clang)"
wait_beside libFuzzer
echo "test.sh: libFuzzer build done at ${SECONDS} s"
(cd build-fuzz && ctest -L fuzz --output-on-failure --no-tests=error -j "$jobs")
echo "test.sh: every stage passed in ${SECONDS} s"
