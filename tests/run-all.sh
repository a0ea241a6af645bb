#!/usr/bin/env bash
# The README's test command: install dependencies, configure, build, run every test.
#   tests/run-all.sh [extra ctest args]
# BUILD_DIR (default build) and JOBS (default 2) may be set.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${BUILD_DIR:-build}
jobs=${JOBS:-2}

deploy/install-deps.sh
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo
cmake --build "$build" -j "$jobs"
ctest --test-dir "$build" --output-on-failure -j "$jobs" "$@"
