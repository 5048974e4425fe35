#!/usr/bin/env bash
# Builds and runs the estimator benchmarks on data/cornell (and the second pass's rays on denser
# scenes besides); writes out/bench/estimators.json and
# prints a table. Repetitions give medians on a noisy machine: BENCH_REPS=3 by default.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh --test
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DQSGI_BUILD_BENCHMARKS=ON > /dev/null
cmake --build build --target qsgi_bench
mkdir -p out/bench
# The dense floor cropped to 8 x 8 tiles, for the second pass's ray benchmark (BM_GatherRays).
python3 scripts/make_bench_scenes.py out/bench/scenes --tiles 8
./build/bench/qsgi_bench --benchmark_repetitions="${BENCH_REPS:-3}" --benchmark_report_aggregates_only=true \
  --benchmark_out=out/bench/estimators.json --benchmark_out_format=json "$@"
