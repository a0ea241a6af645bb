#!/usr/bin/env bash
# The flight recorder on a real kernel's CAN stack, run inside user-mode Linux
# by uml-run.sh (see CMakeLists.txt here):
#
#   record_kernel.sh BUILD_DIR
#
# dh3-service records its socketcan:vcan0 bus (--record) while dh3ctl
# initializes, grasps an object and dh3-sim lets it slip; candump -L records
# the same bus. Every frame the service recorded as received must be in
# candump's log with the same timestamp (both are the kernel's receive
# timestamp of one frame), every frame it sent must be there too, and canplayer
# must play the recording onto a second interface frame for frame.
set -euo pipefail
build=$(cd "${1:?build dir}" && pwd)
here=$(cd "$(dirname "$0")" && pwd)
# shellcheck source=script_lib.sh
source "$here/script_lib.sh"
kernel_script_setup record
extra_cleanup() { ip link del vcan1 2>/dev/null || true; }

ip link show vcan0 >/dev/null 2>&1 || ip link add dev vcan0 type vcan
ip link set up dev vcan0
ip link add dev vcan1 type vcan && ip link set up dev vcan1

stdbuf -oL candump -L vcan0 >"$work/candump.log" 2>"$work/candump.err" &
candump_pid=$!
pids+=($candump_pid)
# Where canplayer will play the recording at the end; nothing is on it before.
stdbuf -oL candump -L vcan1 >"$work/played.log" 2>"$work/played.err" &
played_pid=$!
pids+=($played_pid)

mkfifo "$work/sim.in"
"$sim" --can vcan0 --hands 1 --object 1:40 --init-time-ms 100 \
  <"$work/sim.in" >"$work/sim.out" 2>"$work/sim.err" &
sim_pid=$!
pids+=($sim_pid)
exec 3>"$work/sim.in"
wait_for "$work/sim.out" "serving 1 hands on vcan0" 20 || fail "dh3-sim did not start"

"$service" --name rec --domain "$domain" --bus socketcan:vcan0 --record "$work/rec" \
  >"$work/service.log" 2>&1 &
service_pid=$!
pids+=($service_pid)

ctl() { "$ctl_bin" --domain "$domain" --timeout 30 "$@"; }
for _ in $(seq 60); do
  ctl --json status 2>/dev/null | grep -q '"online":true' && break
  sleep 0.5
done
ctl init rec/vcan0/1 || fail "init"
grasp=$(ctl grasp rec/vcan0/1 50 2>&1) || fail "grasp: $grasp"
grep -q GRASPED <<<"$grasp" || fail "the grasp did not catch: $grasp"
echo "drop 1" >&3
wait_for "$work/sim.out" "^ok drop" 10 || fail "dh3-sim did not drop"
for _ in $(seq 100); do
  ctl --json status rec/vcan0/1 2>/dev/null | grep -q DROPPED && break
  sleep 0.1
done

stop_service "$service_pid"
echo "quit" >&3
exec 3>&-
wait "$sim_pid" || true
kill "$candump_pid" 2>/dev/null || true
wait "$candump_pid" 2>/dev/null || true

recording=$work/rec/vcan0.000001.log
[[ -s $recording ]] || fail "no recording at $recording: $(ls -l "$work/rec" 2>&1)"
echo "---- $(wc -l <"$recording") frames recorded by dh3-service, $(wc -l <"$work/candump.log") by candump"

/usr/bin/python3 - "$recording" "$work/candump.log" <<'PY' || fail "the recording disagrees with candump"
import collections, sys
def lines(path):
    out = []
    for line in open(path):
        parts = line.split()
        if len(parts) >= 3 and parts[0].startswith("("):
            out.append((parts[0], parts[2], parts[3] if len(parts) > 3 else ""))
    return out
recorded, seen = lines(sys.argv[1]), lines(sys.argv[2])
stamped = set((time, frame) for time, frame, _ in seen)
frames = collections.Counter(frame for _, frame, _ in seen)
received = [(t, f) for t, f, d in recorded if d == "R"]
sent = [f for _, f, d in recorded if d == "T"]
missing = [r for r in received if r not in stamped]
print(f"received {len(received)}, sent {len(sent)}; not in candump's log with the same time: {len(missing)}")
for r in missing[:5]:
    print("  ", r)
unseen = collections.Counter(sent) - frames
print(f"sent frames candump never saw: {sum(unseen.values())}")
sys.exit(0 if received and sent and not missing and not unseen else 1)
PY

# canplayer plays the recording onto vcan1 (its bus is named vcan0 in the log).
canplayer -I "$recording" vcan1=vcan0 || fail "canplayer exited $?"
expected=$(wc -l <"$recording")
for _ in $(seq 100); do
  (($(wc -l <"$work/played.log") >= expected)) && break
  sleep 0.05
done
kill "$played_pid" 2>/dev/null || true
# (Files, not <(...): the guest has no /dev/fd.)
awk '{print $3}' "$recording" >"$work/recorded.frames"
awk '{print $3}' "$work/played.log" >"$work/played.frames"
cmp -s "$work/recorded.frames" "$work/played.frames" ||
  fail "canplayer played $(wc -l <"$work/played.log") frames, not the recording's $expected"
echo "canplayer played the $expected frames of the recording in order"
echo "record_kernel: ok"
