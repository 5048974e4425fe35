#!/usr/bin/env bash
# Fuzzes qsgi's input readers with libFuzzer: builds the harnesses of fuzz/ with clang, ASan and
# UBSan in build-fuzz/, then runs each for SECONDS (default 60) on a corpus seeded from data/,
# configs/, tests/data/ and ../shared/data/gltf-samples/ (when present). Prints the executions
# each reached. Exits non-zero if any harness found a crash, leak, hang (> 10 s), sanitizer report
# or uncaught exception; the input that did it is in build-fuzz/artifacts/. Such an input belongs
# in tests/data/bad/<kind>/, listed in tests/data/bad/found.tsv, with the fix.
#   scripts/fuzz.sh [SECONDS] [HARNESS...]   (harnesses: transform_file config gltf)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
harnesses=("${@:2}")
[ ${#harnesses[@]} -eq 0 ] && harnesses=(transform_file config gltf)

scripts/setup.sh --test
cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=clang++ \
  -DQSGI_SANITIZE=ON -DQSGI_BUILD_FUZZERS=ON -DQSGI_BUILD_TESTS=OFF -DQSGI_BUILD_BENCHMARKS=OFF > /dev/null
cmake --build build-fuzz --target "${harnesses[@]/%/_fuzzer}"

# Seeds: copied afresh (read-only for libFuzzer); the corpus it grows stays between runs.
seed() {  # seed HARNESS FILE...
  mkdir -p "build-fuzz/seeds/$1"
  shift_name=$1
  shift
  for f in "$@"; do
    [ -f "$f" ] && [ "$(stat -c %s "$f")" -lt 1000000 ] && cp "$f" "build-fuzz/seeds/$shift_name/$(echo "$f" | tr / _)"
  done
  return 0
}
rm -rf build-fuzz/seeds
shopt -s nullglob globstar
shared=../shared/data/gltf-samples
seed transform_file data/**/animation*.json tests/data/bad/animation/*.json
seed config configs/*.json tests/data/bad/config/*.json
seed gltf data/**/*.gltf data/**/*.glb tests/data/good/* tests/data/bad/gltf/* $shared/**/*.gltf $shared/**/*.glb

# Every check AddressSanitizer has, use of a returned function's stack frame included (the test
# suite under the sanitizers leaves that one to the fuzzers: scripts/test-sanitizers.sh).
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
status=0
mkdir -p build-fuzz/artifacts
# Each harness is one single-threaded process: they run side by side, as many at a time as there
# are cores (QSGI_FUZZ_JOBS overrides), so each still has a core of its own for its SECONDS and the
# stage takes ceil(harnesses / cores) x SECONDS instead of harnesses x SECONDS.
jobs=${QSGI_FUZZ_JOBS:-$(nproc)}
fuzz_one() {  # fuzz_one HARNESS: runs it, its output in build-fuzz/HARNESS.log, exit status its verdict
  "build-fuzz/fuzz/${1}_fuzzer" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=4096 -print_final_stats=1 \
    -dict=fuzz/json.dict -artifact_prefix="build-fuzz/artifacts/$1-" \
    "build-fuzz/corpus/$1" "build-fuzz/seeds/$1" > "build-fuzz/$1.log" 2>&1
}
declare -A pid_of
running=0
for h in "${harnesses[@]}"; do
  mkdir -p "build-fuzz/corpus/$h"
  if [ "$running" -ge "$jobs" ]; then wait -n || true; running=$((running - 1)); fi
  echo "fuzz: $h for ${seconds} s ($(ls "build-fuzz/seeds/$h" | wc -l) seeds)"
  fuzz_one "$h" &
  pid_of[$h]=$!
  running=$((running + 1))
done
for h in "${harnesses[@]}"; do
  log="build-fuzz/$h.log"
  if wait "${pid_of[$h]}"; then
    execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo '?')
    echo "fuzz: $h ok: $execs executions, corpus $(ls "build-fuzz/corpus/$h" | wc -l) inputs"
  else
    status=1
    echo "fuzz: $h FAILED; the report:"
    grep -E 'ERROR|SUMMARY|==[0-9]+==|artifact|Test unit written|runtime error|terminate|deadly' "$log" | head -30
  fi
done
exit $status
