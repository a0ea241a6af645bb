#!/usr/bin/env bash
# A primary and its standby that lose DDS contact but still share the bus:
# three hosts as network namespaces. The transfer box (dh3-sim --shared) is on
# its own host, reached by each service over a link of its own; the services'
# DDS runs over a third link, between them. Cutting that link is the
# partition: the standby sees the primary gone from DDS, but its frames still
# on the bus, so it must not take over (docs/hot-standby.md, the fence on the
# bus): it sends no byte to the box, the primary keeps serving, and once the
# link is back a client on the standby's host is served by the primary as
# before. Then the primary is killed while cut off: the bus goes quiet and the
# standby takes over, as it should, with the hands as they were. Last, a
# primary that leaves the bus quiet is taken over while it lives: when the
# link heals, the older claim stops serving (docs/failover.md, one owner). UDP only, so DDS crosses the veth.
#
#   standby_partition.sh DH3_SERVICE DH3_SIM DH3CTL
# Exit 77 (ctest: skipped) with the reason when namespaces cannot be made.
set -uo pipefail
service_bin=$1 sim_bin=$2 ctl_bin=$3

source "$(dirname "$0")/lib.sh"
tag=dh3p$$
box=$tag-box primary=$tag-pri standby=$tag-sby
sim_pid= primary_pid= standby_pid=
box_port=7000
# The DDS link between the services, and each one's link to the box.
dds_primary=169.254.32.1 dds_standby=169.254.32.2

on_exit() {
  stop_process "$standby_pid"
  stop_process "$primary_pid"
  stop_process "$sim_pid"
}
show_logs() {
  for log in primary standby sim; do
    echo "--- $log log"; tail -n 30 "$work/$log.log" 2>/dev/null
  done
}

require_namespaces
add_hosts "$box" "$primary" "$standby"
link "$primary" 169.254.30.1 "$box" 169.254.30.2 "q${$}p"
link "$standby" 169.254.31.1 "$box" 169.254.31.2 "q${$}s"
link "$primary" "$dds_primary" "$standby" "$dds_standby" "q${$}d"
ip netns exec "$standby" ping -c1 -W2 "$dds_primary" >/dev/null || fail "no link between namespaces"

ip netns exec "$box" "$sim_bin" --listen "0.0.0.0:$box_port" --hands 1,2 --shared \
  --init-time-ms 100 --speed 500 --log-level info >"$work/sim.log" 2>&1 &
sim_pid=$!

# The same cell on both hosts; each reaches the box over its own link.
config() {  # config BOX_ADDRESS
  printf 'name: cell\ndomain: %s\nbuses:\n  - name: box\n    spec: tcp:%s:%s\n    hands: [{id: 1}, {id: 2}]\n' \
    "$domain" "$1" "$box_port"
}
config 169.254.30.2 >"$work/primary.yaml"
config 169.254.31.2 >"$work/standby.yaml"

# wait_for FILE TEXT SECONDS: until FILE holds TEXT; fails after SECONDS.
wait_for() {
  local until=$((SECONDS + $3))
  while ! grep -qF -- "$2" "$1" 2>/dev/null; do
    ((SECONDS < until)) || fail "'$2' not in $(basename "$1") within $3 s"
    sleep 0.1
  done
}
# The bytes the standby's connection has sent to the box (0 if none).
standby_bytes_to_box() {
  ip netns exec "$box" ss -tinH state established "( sport = :$box_port )" dst 169.254.31.1 |
    sed -n 's/.*bytes_received:\([0-9]*\).*/\1/p' | awk '{ n += $1 } END { print n + 0 }'
}
ctl() {  # dh3ctl on the standby's host, over the DDS link only
  ip netns exec "$standby" "$ctl_bin" --domain "$domain" --interface "$dds_standby" --udp-only \
    --timeout 20 "$@"
}

# Each start empties its log first: the shell truncates it only once the
# child runs, and the wait below must not find the last run's line.
start_primary() {  # start_primary CONFIG: the active service, once it serves
  : >"$work/primary.log"
  ip netns exec "$primary" "$service_bin" --config "$1" --interface "$dds_primary" \
    --udp-only --log-level info >"$work/primary.log" 2>&1 &
  primary_pid=$!
  wait_for "$work/primary.log" "service 'cell' on DDS domain" 30
}
start_standby() {  # the standby, once it watches the primary
  : >"$work/standby.log"
  ip netns exec "$standby" "$service_bin" --config "$work/standby.yaml" --role standby \
    --interface "$dds_standby" --udp-only --log-level info >"$work/standby.log" 2>&1 &
  standby_pid=$!
  wait_for "$work/standby.log" "standby: service 'cell' is served by" 30
}

wait_for "$work/sim.log" "serving 2 hand(s)" 15
start_primary "$work/primary.yaml"
start_standby

echo "== a client on the standby's host drives hand 1 through the primary"
ctl init cell/box/1 || fail "init through the primary"
ctl move cell/box/1 40 --wait || fail "move through the primary"

echo "== the DDS link between the services is cut"
ip -n "$primary" link set "q${$}da" down || fail "could not cut the DDS link"
wait_for "$work/standby.log" "its requests are still on the bus: not taking over" 20
# The fence must hold for as long as the primary's frames go on: watch it for
# several of the primary's idle polls and the standby's confirmations.
sleep 5
grep -q "took over" "$work/standby.log" && fail "the standby took over a primary that still drives the bus"
kill -0 "$primary_pid" 2>/dev/null || fail "the primary stopped during the partition"
sent=$(standby_bytes_to_box)
[[ $sent == 0 ]] || fail "the standby sent $sent bytes to the box during the partition"
echo "standby: fenced by the primary's frames, 0 bytes sent to the box"

echo "== the link is back: the primary still serves, the standby still waits"
ip -n "$primary" link set "q${$}da" up || fail "could not restore the DDS link"
ctl move cell/box/1 70 --wait || fail "move through the primary after the partition"
ctl status cell/box/1 | tee "$work/status.out" || fail "status after the partition"
grep -q "took over" "$work/standby.log" && fail "the standby took over after the partition healed"
sent=$(standby_bytes_to_box)
[[ $sent == 0 ]] || fail "the standby sent $sent bytes to the box after the partition"

echo "== cut off again, the primary is killed: the bus goes quiet and the standby takes over"
ip -n "$primary" link set "q${$}da" down || fail "could not cut the DDS link"
kill -KILL "$primary_pid"
wait "$primary_pid" 2>/dev/null
primary_pid=
wait_for "$work/standby.log" "took over from" 20
# A link that is down on one end has no carrier on the other, so the client
# beside the standby needs it back to join DDS.
ip -n "$primary" link set "q${$}da" up || fail "could not restore the DDS link"
ctl move cell/box/1 20 --wait || fail "move through the standby after its takeover"
ctl --json status cell/box/1 | tee "$work/status.json" || fail "status after the takeover"
grep -q '"initialized":true' "$work/status.json" || fail "hand 1 is not initialized after the takeover"
grep -q '"position":20' "$work/status.json" || fail "hand 1 is not at 20 after the takeover's move"

# A primary that sends nothing while its hands are idle leaves the bus quiet:
# cut off, it is taken over although it lives. Two services then serve the
# name, each on its side of the cut; when the link heals the claim of the
# lower epoch stops serving, and one owner is left.
echo "== a quiet primary cut off is taken over; when the link heals it stops"
stop_process "$standby_pid"
standby_pid=
config 169.254.30.2 | sed 's/^    hands/    poll_interval_idle_ms: 60000\n    hands/' >"$work/quiet.yaml"
grep -q "poll_interval_idle_ms: 60000" "$work/quiet.yaml" || fail "no quiet configuration"
start_primary "$work/quiet.yaml"
start_standby
ip -n "$primary" link set "q${$}da" down || fail "could not cut the DDS link"
wait_for "$work/standby.log" "took over from" 20
kill -0 "$primary_pid" 2>/dev/null || fail "the cut-off primary stopped before the link healed"
ip -n "$primary" link set "q${$}da" up || fail "could not restore the DDS link"
wait_for "$work/primary.log" "which outranks this one (epoch 1): this service stops serving" 30
wait "$primary_pid"
code=$?
primary_pid=
[[ $code == 3 ]] || fail "the outranked primary exited $code, not 3 (it lost the name)"
ctl move cell/box/1 50 --wait || fail "move through the service left after the heal"
echo "PASS: fenced while the primary drove the bus, took over once it was dead or quiet, one owner after the heal"
