#!/usr/bin/env bash
# Runs every benchmark on this machine, prints its table and writes its JSON
# into BENCH_OUT (default build/bench). Figures compared with each other come
# from the same run on the same machine.
#   tests/bench/run-benchmarks.sh
set -euo pipefail
cd "$(dirname "$0")/../.."
build=${BUILD_DIR:-build}
out=${BENCH_OUT:-$build/bench}
deploy/install-deps.sh
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build "$build" -j "${JOBS:-2}" --target bench_bus_efficiency
mkdir -p "$out"
"$build/tests/bench/bench_bus_efficiency" --seconds 5 --json "$out/bus_efficiency.json"
echo "JSON written to $out/"
