#!/usr/bin/env bash
# Regenerates tests/golden/*.exr from the current build, on purpose: run it when a change is
# meant to alter the renders (a new estimator default, a fixed bug, a changed scene), then look
# at the new images and commit them with a message that says why they changed.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build build
QSGI_UPDATE_GOLDENS=1 ./build/tests/qsgi_tests --gtest_filter='Renders/GoldenImage.*'
git status --short tests/golden
