#!/usr/bin/env bash
# The image run for real: dh3-service in a container on its built-in
# simulator, driven by the image's clients (dh3ctl, the pick_loop example) in
# other containers, twice:
#   host network  service and clients share the host's network (UDP only, on
#                 loopback: --interface 127.0.0.1 keeps the traffic off the
#                 host's NICs), the root file system read-only as in the
#                 Kubernetes manifests (no tmpfs either);
#   bridge        the image's default configuration (every interface, UDP
#                 only) on podman's default bridge network, its metrics port
#                 published on the host's loopback.
# Then the image's configuration in a shared network namespace with a NIC (as
# on a host's network): a client reaches it with --interface '*', not with
# dh3ctl's loopback-only default.
# Each time: the health check turns healthy (`podman healthcheck run`: no
# systemd schedules it here), the service runs as user 10001, the metrics
# port answers from outside the container, the clients list, initialize,
# move and grasp, and `podman stop` ends the service with exit 0 after it
# published its hands offline (seen by an event watcher in a container).
#
#   test_run.sh SOURCE_DIR
# Exit 77 (skipped) with the reason where no container engine can run.
SRC=$1
source "$(dirname "$0")/lib.sh"
require_image

health() { podman healthcheck run "$1" >/dev/null 2>&1; }
# check_service NAME METRICS_HOST METRICS_PORT CLIENT_ARGS...: the checks both
# networks share. CLIENT_ARGS: podman options, then the client's DDS options.
check_service() {
  local name=$run_id-$1 host=$2 port=$3
  shift 3
  local podman_args=() dds_args=()
  while (($#)) && [[ $1 != -- ]]; do podman_args+=("$1"); shift; done
  shift
  dds_args=("$@" --domain "$domain")
  ctl() { client "${podman_args[@]}" --entrypoint dh3ctl "$image" "${dds_args[@]}" "$@"; }

  if wait_for 90 health "$name"; then
    ok "health check: $(podman inspect --format '{{.State.Health.Status}}' "$name")"
  else
    fail "the health check never passed: $(podman healthcheck run "$name" 2>&1 | tail -n 2)"
    podman logs "$name" 2>&1 | tail -n 20 | sed 's/^/  /'
  fi
  local pid uid
  pid=$(podman inspect --format '{{.State.Pid}}' "$name")
  uid=$(awk '/^Uid:/ {print $2}' "/proc/$pid/status" 2>/dev/null)
  [[ $uid == 10001 ]] && ok "dh3-service runs as user $uid (seen from the host)" ||
    fail "dh3-service runs as user '$uid', not 10001"

  # An event watcher for the offline events at the end.
  container "$1-events" "${podman_args[@]}" --entrypoint dh3ctl "$image" "${dds_args[@]}" \
    --timeout 60 events || return

  if ctl --timeout 30 list >"$work/list" 2>&1 && [[ $(grep -c '^cell/bus0/[123] .* yes ' "$work/list") == 3 ]]; then
    ok "dh3ctl list: 3 hands online"
  else
    fail "dh3ctl list:"; sed 's/^/  /' "$work/list"
  fi
  # move replies once the motion started: the hand arrives a moment later.
  at_30() { ctl --json --timeout 30 status cell/bus0/1 >"$work/status" 2>&1 && grep -q '"position":30,' "$work/status"; }
  if ctl --timeout 30 init cell/bus0/1 >"$work/out" 2>&1 && ctl --timeout 30 move cell/bus0/1 30 >>"$work/out" 2>&1 &&
    wait_for 30 at_30; then
    ok "dh3ctl init, move to 30: the hand arrives at 30"
  else
    fail "dh3ctl init/move/status:"; sed 's/^/  /' "$work/out" "$work/status"
  fi
  if client "${podman_args[@]}" --entrypoint pick_loop "$image" "${dds_args[@]}" \
    --hand cell/bus0/2 --cycles 3 >"$work/pick" 2>&1 && grep -q '^done: 3 cycles, 3 grasped' "$work/pick"; then
    ok "pick_loop: $(tail -n 1 "$work/pick")"
  else
    fail "pick_loop:"; sed 's/^/  /' "$work/pick"
  fi
  if http_get "$host" "$port" /metrics >"$work/metrics" &&
    grep -q '^dh3_hand_online{.*} 1' "$work/metrics"; then
    ok "metrics at http://$host:$port/metrics from the host: $(grep -c '^dh3_hand_online{.*} 1' "$work/metrics") hands online"
  else
    fail "no dh3_hand_online at http://$host:$port/metrics"
  fi

  podman stop -t 30 "$name" >/dev/null 2>&1
  local code
  code=$(exit_code "$name")
  [[ $code == 0 ]] && ok "podman stop: dh3-service exited 0" ||
    { fail "podman stop: dh3-service exited $code"; podman logs "$name" 2>&1 | tail -n 10 | sed 's/^/  /'; }
  local events=$run_id-$1-events
  offline() { [[ $(podman logs "$events" 2>&1 | grep -c 'OFFLINE.*service stopping') == 3 ]]; }
  if wait_for 30 offline; then
    ok "the event watcher saw all 3 hands go OFFLINE (service stopping)"
  else
    fail "the event watcher did not see 3 hands go offline:"; podman logs "$events" 2>&1 | sed 's/^/  /'
  fi
  podman rm -f -t 0 "$events" >/dev/null 2>&1
}

echo "== host network, read-only root file system"
metrics_port=$(free_port)
container host --network=host --read-only --read-only-tmpfs=false \
  -e DH3_DOMAIN="$domain" -e DH3_HEALTH_INTERFACE=127.0.0.1 "$image" \
  --config /etc/dh3/dh3.yaml --domain "$domain" --interface 127.0.0.1 \
  --metrics "127.0.0.1:$metrics_port" &&
  check_service host 127.0.0.1 "$metrics_port" --network=host -- --udp-only --interface 127.0.0.1

echo "== default bridge network, the image's configuration"
metrics_port=$(free_port)
container bridge -p "127.0.0.1:$metrics_port:9464" -e DH3_DOMAIN="$domain" "$image" \
  --config /etc/dh3/dh3.yaml --domain "$domain" &&
  check_service bridge 127.0.0.1 "$metrics_port" -- --udp-only --interface '*'

echo "== the image's configuration on a host's network: clients need --interface '*'"
# A network namespace of this test with a NIC (a veth pair, 169.254.x)
# stands in for the host's network, so the image's "every interface" stays
# off the real NICs; containers join it as they would the host's.
ns=$run_id
if ip netns add "$ns" 2>"$work/err"; then
  cleanup_hooks+=("ip netns del $ns")
  ip -n "$ns" link set lo up
  ip -n "$ns" link add nic0 type veth peer name nic1 && ip -n "$ns" addr add 169.254.77.1/24 dev nic0 &&
    ip -n "$ns" link set nic0 up && ip -n "$ns" link set nic1 up || fail "no veth pair in $ns"
  net=(--network "ns:/run/netns/$ns")
  if container ns "${net[@]}" -e DH3_DOMAIN="$domain" "$image" --config /etc/dh3/dh3.yaml --domain "$domain"; then
    wait_for 90 health "$run_id-ns" || fail "the service in $ns never turned healthy"
    if client "${net[@]}" --entrypoint dh3ctl "$image" --udp-only --domain "$domain" --timeout 8 list \
      >"$work/list" 2>&1; then
      fail "a loopback-only client found the service on every interface (docs/operations.md says it does not)"
    else
      ok "dh3ctl's loopback default does not reach it: $(tail -n 1 "$work/list")"
    fi
    if client "${net[@]}" --entrypoint dh3ctl "$image" --udp-only --interface '*' --domain "$domain" \
      --timeout 30 list >"$work/list" 2>&1 && [[ $(grep -c '^cell/bus0/[123] .* yes ' "$work/list") == 3 ]]; then
      ok "dh3ctl --interface '*' lists its 3 hands"
    else
      fail "dh3ctl --interface '*':"; sed 's/^/  /' "$work/list"
    fi
  fi
else
  fail "ip netns add: $(cat "$work/err")"
fi

finish "container run"
