#!/usr/bin/env bash
# Discovery through a Fast DDS discovery server, across a router that passes
# no multicast: dh3-service on one link, the clients on another, and the
# discovery server (what `fastdds discovery -i 0 -l ADDR -p PORT` runs) on the
# router between them, listening on both links. Link-local addresses; UDP only
# (no shared memory), so everything crosses the veth links.
#
#   srv 169.254.40.2 --- 169.254.40.1 [rtr: forwards unicast, discovery server] 169.254.41.1 --- 169.254.41.2 cli
#
# 1. Without the server the client does not find the service: no multicast
#    path, so simple discovery cannot work here.
# 2. With it, dh3-service (its --discovery-server option, or
#    ROS_DISCOVERY_SERVER), dh3ctl (--discovery-server, and
#    ROS_DISCOVERY_SERVER) and a client-library program (ROS_DISCOVERY_SERVER)
#    find each other through it, and commands work.
#
#   discovery_server.sh DH3_SERVICE DH3CTL PICK_LOOP
# Exit 77 (ctest: skipped) with the reason when namespaces cannot be made.
set -uo pipefail
service_bin=$1 ctl_bin=$2 pick_bin=$3

source "$(dirname "$0")/lib.sh"
tag=ds$$
srv=$tag-srv rtr=$tag-rtr cli=$tag-cli
port=$((20000 + $$ % 20000))
srv_addr=169.254.40.2 srv_gw=169.254.40.1 cli_addr=169.254.41.2 cli_gw=169.254.41.1
service_pid=
server_pid=

stop_service() {
  stop_process "$service_pid"
  service_pid=
}
on_exit() {
  stop_service
  stop_process "$server_pid"
}
show_logs() {
  echo "--- dh3-service log"; tail -n 30 "$work/service.log" 2>/dev/null
  echo "--- discovery server log"; tail -n 10 "$work/server.log" 2>/dev/null
}

require_namespaces
server_bin=$(command -v fast-discovery-server) || fail "fast-discovery-server (package fastdds-tools) is not installed"
add_hosts "$srv" "$rtr" "$cli"
link "$srv" "$srv_addr" "$rtr" "$srv_gw" "d${$}s"
link "$cli" "$cli_addr" "$rtr" "$cli_gw" "d${$}c"
# The router forwards unicast between the links; nothing forwards multicast.
ip netns exec "$rtr" sysctl -qw net.ipv4.ip_forward=1 || fail "cannot enable forwarding"
ip -n "$srv" route add default via "$srv_gw" && ip -n "$cli" route add default via "$cli_gw" ||
  fail "cannot add routes"

start_service() {  # start_service [ENV=VALUE] [OPTIONS...]
  local env=()
  [[ ${1:-} == *=* ]] && { env=("$1"); shift; }
  ip netns exec "$srv" env "${env[@]}" "$service_bin" --domain "$domain" --name cell \
    --bus sim:1,2,3 --interface "$srv_addr" --udp-only --log-level info "$@" \
    >"$work/service.log" 2>&1 &
  service_pid=$!
}
ctl() {  # ctl ARGS...: dh3ctl on the client link
  ip netns exec "$cli" "$ctl_bin" --domain "$domain" --interface "$cli_addr" --udp-only "$@"
}
served() {  # served ARGS...: dh3ctl through the discovery server
  ctl --timeout 20 --discovery-server "$cli_gw:$port" "$@"
}

echo "== without a discovery server the client does not find the service (no multicast path)"
start_service
if ctl --timeout 8 status cell/bus0/1 >"$work/ctl.out" 2>&1; then
  cat "$work/ctl.out"
  fail "the client found the service without a discovery server: the links pass multicast"
fi
grep -q NO_SERVICE "$work/ctl.out" || { cat "$work/ctl.out"; fail "expected NO_SERVICE"; }
sed 's/^/  /' "$work/ctl.out"
stop_service

echo "== discovery server id 0 on the router, $srv_gw:$port and $cli_gw:$port"
ip netns exec "$rtr" "$server_bin" -i 0 -l "$srv_gw" -p "$port" -l "$cli_gw" -p "$port" \
  >"$work/server.log" 2>&1 &
server_pid=$!
for _ in $(seq 200); do
  ip netns exec "$rtr" ss -H -uln "sport = :$port" | grep -q . && break
  kill -0 "$server_pid" 2>/dev/null || fail "the discovery server exited"
  sleep 0.05
done
ip netns exec "$rtr" ss -H -uln "sport = :$port" | grep -q . || fail "the discovery server does not listen on $port"

echo "== dh3-service with --discovery-server $srv_gw:$port"
start_service --discovery-server "$srv_gw:$port"

step "list through the server" served list
step "init hand 1" served init cell/bus0/1
step "move hand 1" served move cell/bus0/1 60
echo "== status of hand 1 (position 60)"
ctl --timeout 20 --discovery-server "$cli_gw:$port" --json status cell/bus0/1 >"$work/status.json" ||
  fail "status of hand 1"
cat "$work/status.json"
grep -q '"position":60' "$work/status.json" || fail "hand 1 is not at 60"

echo "== dh3ctl with ROS_DISCOVERY_SERVER=$cli_gw:$port"
ip netns exec "$cli" env "ROS_DISCOVERY_SERVER=$cli_gw:$port" "$ctl_bin" --domain "$domain" \
  --interface "$cli_addr" --udp-only --timeout 20 grasp cell/bus0/1 40 || fail "grasp via ROS_DISCOVERY_SERVER"

echo "== client-library program (pick_loop) with ROS_DISCOVERY_SERVER=$cli_gw:$port"
ip netns exec "$cli" env "ROS_DISCOVERY_SERVER=$cli_gw:$port" "$pick_bin" --domain "$domain" \
  --interface "$cli_addr" --udp-only --hand cell/bus0/3 --cycles 2 || fail "pick loop"

stop_service
echo "== dh3-service again, with ROS_DISCOVERY_SERVER=$srv_gw:$port instead of the option"
start_service "ROS_DISCOVERY_SERVER=$srv_gw:$port"
step "status of hand 2" served status cell/bus0/2

echo "discovery-server: all steps passed"
