#!/usr/bin/env bash
# The shared-memory pitfall the README's deployment section describes, shown
# with what containers are made of: two participants that Fast DDS takes to
# be on the same host (one network namespace, so the same addresses) but that
# do not share /dev/shm (a private mount of it, as in a container without
# --ipc=host). Fast DDS then sends the data through shared memory that the
# other side cannot see: the client finds the service but gets no status. With
# the service UDP only it works; so it does with /dev/shm shared.
#
#   test_shm_pitfall.sh DH3_SERVICE DH3CTL
# Exit 77 (skipped) with the reason where namespaces cannot be made.
set -uo pipefail
service_bin=$1 ctl_bin=$2
ns=shm$$
domain=$((10 + $$ % 200))
work=$(mktemp -d)
service_pid=
stop_service() {
  if [[ -n $service_pid ]]; then
    kill -TERM "$service_pid" 2>/dev/null
    wait "$service_pid" 2>/dev/null
    service_pid=
  fi
}
cleanup() {
  stop_service
  ip netns del "$ns" 2>/dev/null
  rm -rf "$work"
}
trap cleanup EXIT
skip() { echo "SKIP: $*"; exit 77; }
failures=0
fail() { echo "FAILED: $*"; failures=$((failures + 1)); }
ok() { echo "ok: $*"; }

[[ $(id -u) -eq 0 ]] || skip "needs root for a network namespace and a private /dev/shm"
ip netns add "$ns" 2>"$work/err" || skip "ip netns add failed: $(cat "$work/err")"
ip -n "$ns" link set lo up
unshare -m true 2>/dev/null || skip "cannot make a mount namespace"

start_service() {  # start_service [--udp-only]
  ip netns exec "$ns" "$service_bin" --name shm --domain "$domain" --bus sim:1 "$@" \
    >"$work/service.log" 2>&1 &
  service_pid=$!
}
# dh3ctl in the same network namespace; "own" gives it a /dev/shm of its own.
status() {  # status shared|own TIMEOUT
  if [[ $1 == own ]]; then
    ip netns exec "$ns" unshare -m sh -c 'mount -t tmpfs dh3-private-shm /dev/shm && exec "$@"' \
      sh "$ctl_bin" --domain "$domain" --timeout "$2" status shm/bus0/1
  else
    ip netns exec "$ns" "$ctl_bin" --domain "$domain" --timeout "$2" status shm/bus0/1
  fi >"$work/ctl.out" 2>&1
}

start_service
status shared 20 && ok "shared /dev/shm, shared memory on: the client gets the status" ||
  { cat "$work/ctl.out"; fail "shared /dev/shm: no status"; }
if status own 8; then
  cat "$work/ctl.out"
  fail "private /dev/shm, shared memory on: the client got the status (the pitfall is gone?)"
else
  ok "private /dev/shm, shared memory on: no status ($(tail -n 1 "$work/ctl.out"))"
fi
stop_service

start_service --udp-only
status own 20 && ok "private /dev/shm, service UDP only: the client gets the status" ||
  { cat "$work/ctl.out"; fail "private /dev/shm, UDP only: no status"; }
stop_service

if ((failures)); then
  echo "$failures failure(s)"
  exit 1
fi
echo "shared-memory pitfall: as documented"
