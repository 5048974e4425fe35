#!/usr/bin/env bash
# Sets up (the Debian packages building and rendering need), builds and renders the default example: data/cornell with its
# 60-frame animation into out/cornell/ (configs/default.json). Extra arguments go to qsgi render.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
# Only the renderer: the tests and benchmarks (and what they need) are the test command's.
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DQSGI_BUILD_TESTS=OFF -DQSGI_BUILD_BENCHMARKS=OFF > /dev/null
cmake --build build --target qsgi
# qsgi's last line says how many frames it wrote and where (out/cornell unless --out says otherwise).
./build/cli/qsgi render --config configs/default.json "$@"
