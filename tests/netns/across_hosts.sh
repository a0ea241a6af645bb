#!/usr/bin/env bash
# "Client on another host", for real: three network namespaces joined by veth
# pairs with link-local addresses. dh3-service runs in one, on the simulator;
# dh3ctl and a client-library program run in the two others. UDP only (no shared
# memory), so every sample crosses a veth link. Deletes what it made on exit.
#
#   across_hosts.sh DH3_SERVICE DH3CTL PICK_LOOP
# Exit 77 (ctest: skipped) with the reason when namespaces cannot be made.
set -uo pipefail
service_bin=$1 ctl_bin=$2 pick_bin=$3

source "$(dirname "$0")/lib.sh"
tag=dh3$$
srv=$tag-srv cli_a=$tag-a cli_b=$tag-b
service_pid=

on_exit() {
  stop_process "$service_pid"
}
show_logs() {
  echo "--- dh3-service log"; tail -n 40 "$work/service.log" 2>/dev/null
}

require_namespaces
add_hosts "$srv" "$cli_a" "$cli_b"
# srv <-> a on 169.254.10.0/24, srv <-> b on 169.254.11.0/24
link "$srv" 169.254.10.1 "$cli_a" 169.254.10.2 "v${$}a"
link "$srv" 169.254.11.1 "$cli_b" 169.254.11.2 "v${$}b"
ip netns exec "$cli_a" ping -c1 -W2 169.254.10.1 >/dev/null || fail "no link between namespaces"

ip netns exec "$srv" "$service_bin" --domain "$domain" --name cell --bus sim:1,2,3 \
  --interface 169.254.10.1 --interface 169.254.11.1 --udp-only --log-level info \
  >"$work/service.log" 2>&1 &
service_pid=$!

ctl() {  # ctl NS ARGS...: dh3ctl in that client namespace over its veth only
  local ns=$1 addr; shift
  [[ $ns == "$cli_a" ]] && addr=169.254.10.2 || addr=169.254.11.2
  ip netns exec "$ns" "$ctl_bin" --domain "$domain" --interface "$addr" --udp-only --timeout 20 "$@"
}

step "list from host a" ctl "$cli_a" list
step "init hand 1 from host a" ctl "$cli_a" init cell/bus0/1
step "move hand 1 from host a" ctl "$cli_a" move cell/bus0/1 60
step "status of hand 1 from host a" ctl "$cli_a" status cell/bus0/1
step "grasp hand 1 from host a" ctl "$cli_a" grasp cell/bus0/1 40

# Two client hosts at once: the same hand, and different hands.
echo "== host a and host b together"
ctl "$cli_b" init cell/bus0/2 >"$work/b-init.out" 2>&1 &
b_init=$!
ctl "$cli_a" move cell/bus0/1 80 >"$work/a-move.out" 2>&1 &
a_move=$!
wait $b_init || { cat "$work/b-init.out"; fail "init hand 2 from host b"; }
wait $a_move || { cat "$work/a-move.out"; fail "move hand 1 from host a"; }
ctl "$cli_a" move cell/bus0/2 30 >"$work/a.out" 2>&1 &
a_pid=$!
ctl "$cli_b" move cell/bus0/2 70 >"$work/b.out" 2>&1 &
b_pid=$!
# Both hosts move the same hand at once: the last command wins, as on the
# hand itself. A move superseded before it was sent ends CANCELLED; at least
# one must succeed, and nothing else is acceptable.
moved=0
for who in a b; do
  pid_var=${who}_pid
  if wait "${!pid_var}"; then
    moved=$((moved + 1))
  elif ! grep -q CANCELLED "$work/$who.out"; then
    cat "$work/$who.out"; fail "host $who moving hand 2"
  fi
done
((moved > 0)) || fail "neither host's move of hand 2 succeeded"
step "status of hand 2 from host b" ctl "$cli_b" --json status cell/bus0/2

echo "== client-library program on host b"
ip netns exec "$cli_b" "$pick_bin" --domain "$domain" --interface 169.254.11.2 --udp-only \
  --hand cell/bus0/3 --cycles 2 || fail "pick loop on host b"

echo "across-hosts: all steps passed"
