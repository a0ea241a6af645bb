#!/usr/bin/env bash
# Clients started together: SERVICES dh3-service processes with
# their simulated hands, then CLIENTS dh3ctl processes started at the same
# moment, each reading one hand's position, with BUSY busy loops on the CPU
# beside them. Every client must be answered; the script counts each
# outcome and prints the failures' messages. docs/operations.md's default transports
# throughout (no transport option given to anyone).
#
#   client_burst.sh DH3_SERVICE DH3CTL [CLIENTS [SERVICES [BUSY]]]
#
# Defaults: 32 clients, 1 service, 2 busy loops. Prints one summary line
# "burst: CLIENTS clients, SERVICES services, BUSY busy loops: N answered,
# M failed; seconds p50 X max Y" (times are reported, never asserted).
set -euo pipefail
service_bin=${1:?dh3-service path}
ctl_bin=${2:?dh3ctl path}
clients=${3:-32}
services=${4:-1}
busy=${5:-2}
work=$(mktemp -d /tmp/dh3-burst.XXXXXX)
# A domain of its own (sets $domain): other tests run beside it.
# shellcheck source=../support/test_domain.sh
source "$(dirname "$0")/../support/test_domain.sh"
prefix=burst$$
# shellcheck source=../support/processes.sh
source "$(dirname "$0")/../support/processes.sh"
fail() {
  echo "FAIL: $*"
  for f in "$work"/service*.log; do
    [[ -f $f ]] && { echo "---- $(basename "$f") (last 20 lines)"; tail -n 20 "$f"; }
  done
  exit 1
}

for s in $(seq 1 "$services"); do
  "$service_bin" --name "$prefix-$s" --domain "$domain" --log-level warn \
    >"$work/service$s.log" 2>&1 &
  pids+=($!)
done
# Each service answers one client before the burst, so the burst measures
# clients starting, not services starting.
for s in $(seq 1 "$services"); do
  "$ctl_bin" --domain "$domain" --timeout 60 read "$prefix-$s/bus0/1" position \
    >/dev/null 2>"$work/warmup$s.err" || fail "service $s never answered: $(cat "$work/warmup$s.err")"
done

# Bounded busy loops: they end by themselves even if this script is killed.
for _ in $(seq 1 "$busy"); do
  timeout 300 bash -c 'while :; do :; done' &
  pids+=($!)
done

# Every client waits for one file to appear, so they start within a few
# milliseconds of each other.
client_pids=()
for i in $(seq 1 "$clients"); do
  s=$(((i - 1) % services + 1))
  hand=$(((i - 1) % 3 + 1))
  (
    until [[ -e $work/go ]]; do sleep 0.005; done
    started=$(date +%s%N)
    rc=0
    "$ctl_bin" --domain "$domain" --timeout 30 read "$prefix-$s/bus0/$hand" position \
      >"$work/client$i.out" 2>"$work/client$i.err" || rc=$?
    echo "$rc $(($(date +%s%N) - started))" >"$work/client$i.rc"
  ) &
  client_pids+=($!)
done
sleep 0.5
touch "$work/go"
wait "${client_pids[@]}" || true
for pid in "${pids[@]:services}"; do kill "$pid" 2>/dev/null || true; done

answered=0
failed=0
times=()
for i in $(seq 1 "$clients"); do
  if [[ ! -s $work/client$i.rc ]]; then
    failed=$((failed + 1))
    echo "client $i: no outcome recorded"
    continue
  fi
  read -r rc ns <"$work/client$i.rc"
  times+=("$ns")
  if [[ $rc -eq 0 ]] && grep -q '[0-9]' "$work/client$i.out"; then
    answered=$((answered + 1))
  else
    failed=$((failed + 1))
    echo "client $i: exit $rc: $(tr '\n' ' ' <"$work/client$i.err" | cut -c1-300)"
  fi
done
sorted=$(printf '%s\n' "${times[@]}" | sort -n)
ms() { echo "scale=2; $1 / 1000000000" | bc; }
p50=$(ms "$(sed -n "$(((${#times[@]} + 1) / 2))p" <<<"$sorted")")
max=$(ms "$(tail -n 1 <<<"$sorted")")
echo "burst: $clients clients, $services services, $busy busy loops: $answered answered," \
  "$failed failed; seconds p50 $p50 max $max"
((failed == 0)) || fail "$failed of $clients clients were not answered"
echo "all $clients clients answered"
