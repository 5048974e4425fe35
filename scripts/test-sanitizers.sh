#!/usr/bin/env bash
# Builds qsgi with AddressSanitizer and UndefinedBehaviorSanitizer (GCC, -DQSGI_SANITIZE=ON) in
# build-asan/ and runs the test suite there. Every sanitizer report aborts the process, so it fails
# the test that provoked it, including reports from the qsgi executable the CLI tests run.
# Extra arguments go to ctest (e.g. -R Cli).
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Release -DQSGI_SANITIZE=ON -DQSGI_BUILD_BENCHMARKS=OFF
cmake --build build-asan
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
cd build-asan
ctest --output-on-failure -j 2 "$@"
