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
cmake --build "$build" -j "${JOBS:-2}" --target bench_bus_efficiency bench_round_trip \
  bench_status_fanout bench_footprint bench_event_latency bench_cell bench_group_skew \
  dh3-service dh3ctl dh3-web dh3_python
mkdir -p "$out"
bench="$build/tests/bench"
# 1 and 2: round trip vs raw Fast DDS (shm and UDP), five runs and their median
# ratios, service overhead (~4 min).
"$bench/bench_round_trip" --count 5000 --runs 5 --json "$out/round_trip.json"
echo
# 3: bus efficiency (simulated time, ~30 s).
"$bench/bench_bus_efficiency" --seconds 5 --json "$out/bus_efficiency.json"
echo
# 10: group command skew on the simulated line, hands answering at once and
# after 2 ms (~10 s).
"$bench/bench_group_skew" --rounds 30
"$bench/bench_group_skew" --rounds 30 --reply-delay-us 2000
echo
# 4: status fan-out to 1, 4 and 16 client processes (~30 s).
"$bench/bench_status_fanout" --seconds 5 --json "$out/status_fanout.json"
echo
# 5: footprint with 1, 32 and 255 hands (~50 s; CPU time has 10 ms ticks).
"$bench/bench_footprint" --warmup 3 --seconds 10 --json "$out/footprint.json"
echo
# 7: event latency, simulated change to the event at a client process (~2 min).
"$bench/bench_event_latency" --cycles 20 --many-cycles 40 --json "$out/event_latency.json"
echo
# 8: a cell of 1, 4 and 16 client processes commanding at once (~1 min).
"$bench/bench_cell" --count 1000 --json "$out/cell.json"
echo
# Death detection's cost at rest: the owner liveliness to 1, 4 and 16 clients
# on loopback, captured by tshark (~1.5 min).
for clients in 1 4 16; do tests/bench/liveliness-cost.sh "$build" "$clients" 20; done
echo
# Death detection by client kind: the Python module, dh3ctl events and
# dh3-web's stream, SIGKILL and SIGSTOP of the service, 20 each (~2 min).
for sig in KILL STOP; do
  /usr/bin/python3 tests/bench/death-by-client.py --build "$build" --kills 20 --signal "$sig" \
    --json "$out/death_by_client_$sig.json"
done
echo "JSON written to $out/"
