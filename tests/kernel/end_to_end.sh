#!/usr/bin/env bash
# dh3 end to end on a real kernel's CAN stack, run inside user-mode Linux by
# uml-run.sh (see CMakeLists.txt here):
#
#   end_to_end.sh BUILD_DIR vcan    dh3-service on socketcan:vcan0, dh3-sim on vcan0
#   end_to_end.sh BUILD_DIR vxcan   the hands on one end of a vxcan pair in a network
#                                   namespace of their own, the service on the other
#                                   (how a CAN interface is handed to a container)
#
# dh3ctl initializes, moves, rotates, sets the force, grasps with and without
# an object, releases, stops a motion and reads the firmware; every command must
# succeed with the expected result. candump records the bus; check_frames.py
# checks every frame against the protocol document, and (vxcan: candump tells
# the service's frames from the hands') the 20 ms per-hand interval on the
# kernel's timestamps. dh3-sim --min-interval-ms 20 must count no frame to a
# hand sooner than 20 ms after the previous one.
set -euo pipefail
build=$(cd "${1:?build dir}" && pwd)
mode=${2:?vcan or vxcan}
here=$(cd "$(dirname "$0")" && pwd)
# shellcheck source=script_lib.sh
source "$here/script_lib.sh"
kernel_script_setup e2e
extra_cleanup() { ip netns del dh3hands 2>/dev/null || true; }

case $mode in
  vcan)
    iface=vcan0
    sim_iface=vcan0
    sim_in=()
    marks=()
    ip link show vcan0 >/dev/null 2>&1 || ip link add dev vcan0 type vcan
    ip link set up dev vcan0
    ;;
  vxcan)
    iface=dh3svc
    sim_iface=dh3hands
    ip netns add dh3hands
    ip link add "$iface" type vxcan peer name "$sim_iface" netns dh3hands
    ip link set up dev "$iface"
    ip netns exec dh3hands ip link set up dev "$sim_iface"
    sim_in=(ip netns exec dh3hands)
    marks=(--service-marks T)
    ;;
  *) fail "unknown mode $mode" ;;
esac

# Line-buffered: the stop below waits for a frame to appear in this log.
stdbuf -oL candump -L -x "$iface" >"$work/bus.log" 2>"$work/candump.err" &
pids+=($!)

mkfifo "$work/sim.in"
"${sim_in[@]}" "$sim" --can "$sim_iface" --hands 1,2 --object 2:40 --min-interval-ms 20 \
  --init-time-ms 300 <"$work/sim.in" >"$work/sim.out" 2>"$work/sim.err" &
sim_pid=$!
pids+=($sim_pid)
exec 3>"$work/sim.in"  # the sim's control channel stays open until we close it
wait_for "$work/sim.out" "serving 2 hands on $sim_iface" 20 || fail "dh3-sim did not start"

cat >"$work/service.yaml" <<YAML
name: e2e
domain: $domain
buses:
  - name: can
    spec: socketcan:$iface
    bit_rate: 500000
    hands: [{id: 1, name: left}, {id: 2, name: right}]
YAML
"$service" --config "$work/service.yaml" --log-level info >"$work/service.log" 2>&1 &
service_pid=$!
pids+=($service_pid)

ctl() { "$ctl_bin" --domain "$domain" --timeout 30 "$@"; }
expect() {  # expect PATTERN dh3ctl-args...: runs dh3ctl, which must succeed and print PATTERN
  local pattern=$1 out
  shift
  echo "\$ dh3ctl $*"
  out=$(ctl "$@" 2>&1) || fail "dh3ctl $* exited $?: $out"
  echo "$out" | sed 's/^/  /'
  grep -q -- "$pattern" <<<"$out" || fail "dh3ctl $*: no '$pattern' in its output"
}

for _ in $(seq 60); do
  online=$(ctl --json status 2>/dev/null | grep -c '"online":true' || true)
  ((online == 2)) && break
  sleep 0.5
done
((online == 2)) || fail "the hands never came online on $iface"

expect "" init e2e/can/1
expect "" init e2e/can/2
expect "" move e2e/can/1 30
expect "" rotate e2e/can/1 50
expect "" force e2e/can/2 40
expect GRASPED grasp e2e/can/2 60
expect MISSED grasp e2e/can/1 40
expect "" release e2e/can/2 100
# A stop while the fingers move: the move ends (OK if it arrived first,
# CANCELLED if the stop came in time) and the stop succeeds.
# The stop's dh3ctl starts once the move's frame (position 100 to hand 1) is on
# the bus, not after a fixed sleep, so that the stop reaches fingers in motion.
# (Clients started together are tests/reliability/client_burst.sh's case.)
move_frame='001#0602010064000000'
frames_before=$(grep -c "$move_frame" "$work/bus.log" || true)
ctl move e2e/can/1 100 >"$work/move.out" 2>&1 &
move_pid=$!
for _ in $(seq 1200); do
  (($(grep -c "$move_frame" "$work/bus.log" || true) > frames_before)) && break
  kill -0 "$move_pid" 2>/dev/null || break
  sleep 0.05
done
(($(grep -c "$move_frame" "$work/bus.log" || true) > frames_before)) ||
  fail "the move's frame never reached the bus: $(cat "$work/move.out")"
expect "" stop e2e/can/1
wait "$move_pid" || grep -q CANCELLED "$work/move.out" || fail "the stopped move: $(cat "$work/move.out")"
expect "4.1.2.0" version e2e/can/1

echo "violations" >&3
wait_for "$work/sim.out" "^ok " 10 || fail "dh3-sim did not answer 'violations'"
stop_service "$service_pid"
echo "quit" >&3
exec 3>&-
sim_status=0
wait "$sim_pid" || sim_status=$?
((sim_status == 0)) || fail "dh3-sim exited $sim_status"
kill "${pids[0]}" 2>/dev/null || true  # candump

echo "---- dh3-sim"
cat "$work/sim.out"
grep -q '^interval violations: 0$' "$work/sim.out" ||
  fail "frames to a hand came sooner than 20 ms after the previous one: $(grep -h 'interval' "$work/sim.err" | head -5)"
echo "---- the bus, $(wc -l <"$work/bus.log") frames recorded by candump on $iface"
python3 "$here/check_frames.py" "$work/bus.log" "${marks[@]}" --min-interval-ms 20 --hands 1,2 ||
  fail "frames on the bus break the protocol document"
echo "end_to_end $mode: ok"
