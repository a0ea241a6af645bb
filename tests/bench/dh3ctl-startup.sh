#!/bin/bash
# dh3ctl's start-up to answer (BENCHMARKS.md section 11): RUNS runs of
# `dh3ctl status dh3/bus0/1` one after another against one simulator service,
# each timed as a whole; prints p50, p95, max and the runs over 1 s.
# Usage: tests/bench/dh3ctl-startup.sh [BUILD_DIR] [RUNS] [DOMAIN]
set -euo pipefail
build=${1:-build}
runs=${2:-40}
domain=${3:-217}
service="$build/service/app/dh3-service/dh3-service"
dh3ctl="$build/client/dh3ctl"
"$service" --domain "$domain" --bus sim:1,2,3 >/dev/null 2>&1 &
service_pid=$!
trap 'kill "$service_pid" 2>/dev/null; wait "$service_pid" 2>/dev/null || true' EXIT
# Until the service answers: its own start-up is not what is measured.
until "$dh3ctl" --domain "$domain" --timeout 2 status dh3/bus0/1 >/dev/null 2>&1; do sleep 0.2; done
times=()
for _ in $(seq "$runs"); do
  start=$(date +%s.%N)
  "$dh3ctl" --domain "$domain" status dh3/bus0/1 >/dev/null
  end=$(date +%s.%N)
  times+=("$(echo "$end - $start" | bc)")
  sleep 0.2  # one at a time: a run's participant has left before the next
done
printf '%s\n' "${times[@]}" | sort -n | awk '{t[NR] = $1}
  END {
    n = NR; slow = 0
    for (i = 1; i <= n; i++) if (t[i] > 1.0) slow++
    printf "%d runs: p50 %.3f s, p95 %.3f s, max %.3f s, %d over 1 s\n",
           n, t[int((n + 1) / 2)], t[int(0.95 * n + 0.999)], t[n], slow
  }'
