#!/usr/bin/env bash
# The test command (CI runs it through .ci/run): sets up the Debian packages (scripts/setup.sh --test), then
#   1. builds from scratch (Release) and runs the whole test suite with ctest;
#   2. tests the Slurm job arrays on a single-node cluster it starts (scripts/test-slurm.sh);
#   3. builds with AddressSanitizer + UndefinedBehaviorSanitizer and runs the suite again
#      (scripts/test-sanitizers.sh);
#   4. fuzzes the transform-file, config and glTF readers for QSGI_FUZZ_SECONDS each (default 30;
#      scripts/fuzz.sh).
# QSGI_SKIP_SLURM=1 / QSGI_SKIP_SANITIZERS=1 / QSGI_SKIP_FUZZ=1 leave out 2 / 3 / 4 for a quick
# local run. Extra arguments
# go to ctest in step 1.
set -euo pipefail
cd "$(dirname "$0")/.."
# Each step's wall time on stderr, so that a CI log shows where its minutes went.
step_start=$SECONDS
timed() { echo "test.sh: $1 took $((SECONDS - step_start)) s" >&2; step_start=$SECONDS; }
scripts/setup.sh --test
timed "setup"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DQSGI_BUILD_TESTS=ON -DQSGI_BUILD_BENCHMARKS=ON
cmake --build build
timed "release build"
# A corpus the sanitizer stage (step 3) runs with the same assertions is left to it when it runs:
# HostileInput's bad files (tests/data/bad/: each refused with exit 2, one line naming it, nothing
# written) are checked there, where a hostile byte that reaches memory it should not also fails.
# With QSGI_SKIP_SANITIZERS=1, or when extra arguments choose the tests, they run here.
asan_proves='HostileInput\.EveryBadFileIsRefusedWithOneLineNamingItExitTwoAndNothingWritten'
if [ "${QSGI_SKIP_SANITIZERS:-0}" != 1 ] && [ $# -eq 0 ]; then set -- -E "$asan_proves"; fi
(cd build && ctest --output-on-failure -j 2 "$@")
timed "release suite"
if [ "${QSGI_SKIP_SLURM:-0}" != 1 ]; then scripts/test-slurm.sh; timed "slurm"; fi
if [ "${QSGI_SKIP_SANITIZERS:-0}" != 1 ]; then scripts/test-sanitizers.sh; timed "sanitizer build and suite"; fi
if [ "${QSGI_SKIP_FUZZ:-0}" != 1 ]; then scripts/fuzz.sh "${QSGI_FUZZ_SECONDS:-30}"; timed "fuzz"; fi
