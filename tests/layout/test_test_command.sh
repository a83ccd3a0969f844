#!/usr/bin/env bash
# The test command must test: after scripts/main.sh has configured build/ with
# the tests off, scripts/test.sh configuring the same folder must turn every
# part back on (CMake keeps cached options), and every ctest it runs must fail
# when no test is found. Reproduces the report where CTest printed "No tests
# were found!!!" and passed. Usage: test_test_command.sh SOURCE_ROOT SCRATCH
set -euo pipefail
root=$1
scratch=$2
rm -rf "$scratch"
mkdir -p "$scratch"
fail() { echo "FAIL: $*"; exit 1; }

# Every ctest line of test.sh refuses an empty run.
grep -q 'ctest' "$root/scripts/test.sh" || fail "test.sh runs no ctest"
while IFS= read -r line; do
    [[ $line == *--no-tests=error* ]] || fail "a ctest line of test.sh lacks --no-tests=error: $line"
done < <(grep -E '^[^#]*\bctest\b' "$root/scripts/test.sh")

# main.sh's configure, then test.sh's release configure, in one folder: the
# arguments are read from the scripts themselves, so that they cannot drift.
main_args=$(grep -A1 'scripts/build.sh "\$build"' "$root/scripts/main.sh" | tr -d '\\\n' |
    grep -oE -- '-D[A-Z_]+=[A-Za-z0-9]+' | tr '\n' ' ')
parts=$(grep -E '^parts=\(' "$root/scripts/test.sh" | grep -oE -- '-D[A-Z_]+=[A-Za-z0-9]+' | tr '\n' ' ')
[[ -n $main_args ]] || fail "could not read main.sh's configure options"
[[ -n $parts ]] || fail "could not read test.sh's parts"
echo "main.sh configures with: $main_args"
echo "test.sh configures with: $parts"
count() { (cd "$scratch" && ctest -N | sed -n 's/^Total Tests: //p'); }
# shellcheck disable=SC2086
cmake -S "$root" -B "$scratch" $main_args >/dev/null
before=$(count)
# shellcheck disable=SC2086
cmake -S "$root" -B "$scratch" $parts >/dev/null
n=$(count)
# The Catch2 cases are discovered when their executables are built; before
# any build the scripted tests (pd, pdosc, sound, ui, e2e, layout ...) are there.
echo "tests registered: $before after main.sh's configure, $n after test.sh's (before building)"
grep -q '^ICTUS_BUILD_TESTS:BOOL=ON' "$scratch/CMakeCache.txt" || fail "ICTUS_BUILD_TESTS stays off"
[[ ${n:-0} -ge 20 && ${n:-0} -gt ${before:-0} ]] ||
    fail "test.sh's configure after main.sh's registers ${n:-0} tests"
# And an empty run does fail.
if (cd "$scratch" && ctest -R 'no test has this name' --no-tests=error >/dev/null 2>&1); then
    fail "ctest --no-tests=error passed with no test"
fi
echo "ok: the test command tests"
