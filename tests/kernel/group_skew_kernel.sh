#!/usr/bin/env bash
# Group commands on a real kernel's CAN stack, run inside user-mode Linux by
# uml-run.sh (see CMakeLists.txt here):
#
#   group_skew_kernel.sh BUILD_DIR [ROUNDS] [REPLY_DELAY_MS]
#
# dh3-service on socketcan:vcan0 with 8 hands of dh3-sim --can vcan0; dh3ctl
# sends group MOVEs to 2, 4 and 8 of them, ROUNDS times each (default 5),
# while candump -L records the bus with the kernel's receive timestamps. Each
# group must put one position write per member on the bus, and every command
# must succeed. Prints each size's skew, from the first member's position
# write to the last one's as the kernel timestamped them, next to the floor
# of a 1 Mbit/s line ((N-1) frame times + 0.2 ms; vcan itself takes no line
# time, so what it shows is the service's own spacing of the frames).
set -euo pipefail
build=$(cd "${1:?build dir}" && pwd)
rounds=${2:-5}
reply_delay_ms=${3:-2}  # dh3-sim's: how long a hand takes to answer
here=$(cd "$(dirname "$0")" && pwd)
# shellcheck source=script_lib.sh
source "$here/script_lib.sh"
kernel_script_setup group

ip link show vcan0 >/dev/null 2>&1 || ip link add dev vcan0 type vcan
ip link set up dev vcan0

# A hand's request precedes its reply: the first position write per hand in a
# group is the service's.
"$sim" --can vcan0 --hands 1-8 --init-time-ms 100 --reply-delay-ms "$reply_delay_ms" \
  >"$work/sim.out" 2>"$work/sim.err" &
pids+=($!)
wait_for "$work/sim.out" "serving 8 hands on vcan0" 20 || fail "dh3-sim did not start"

"$service" --name grp --domain "$domain" --bus socketcan:vcan0 >"$work/service.log" 2>&1 &
pids+=($!)
ctl() { "$ctl_bin" --domain "$domain" --timeout 30 "$@"; }
hands=()
for id in $(seq 8); do hands+=("grp/vcan0/$id"); done
for _ in $(seq 60); do
  (($(ctl --json status 2>/dev/null | grep -o '"online":true' | wc -l) >= 8)) && break
  sleep 0.5
done
ctl group init "${hands[@]}" >"$work/init.out" 2>&1 || fail "group init: $(cat "$work/init.out")"

stdbuf -oL candump -L vcan0 >"$work/candump.log" 2>"$work/candump.err" &
candump_pid=$!
pids+=($candump_pid)
sleep 0.5
position=10
for size in 2 4 8; do
  for _ in $(seq "$rounds"); do
    position=$((position == 10 ? 60 : 10))
    ctl group move "${hands[@]:0:size}" --position "$position" >"$work/move.out" 2>&1 ||
      fail "group move of $size hands: $(cat "$work/move.out")"
    echo "$size" >>"$work/sizes"
    # Apart from the next group by far more than a group's spread.
    sleep 0.3
  done
done
sleep 0.2
kill "$candump_pid" 2>/dev/null || true
wait "$candump_pid" 2>/dev/null || true

/usr/bin/python3 - "$work/candump.log" "$work/sizes" <<'PY' || fail "a group's frames were not all on the bus"
import statistics, sys
log, sizes = sys.argv[1], [int(line) for line in open(sys.argv[2])]
writes = []  # (time, hand) of every position write (06 02 01), request or reply
for line in open(log):
    parts = line.split()
    if len(parts) < 3 or not parts[0].startswith("("):
        continue
    can_id, _, data = parts[2].partition("#")
    if data[:6].upper() == "060201":
        writes.append((float(parts[0].strip("()")), int(can_id, 16)))
groups = []  # each group's first position write per hand
for time, hand in writes:
    if not groups or time - groups[-1]["start"] > 0.1:
        groups.append({"start": time, "first": {}})
    groups[-1]["first"].setdefault(hand, time)
if len(groups) != len(sizes):
    print(f"{len(groups)} groups of position writes on the bus, {len(sizes)} group moves sent")
    sys.exit(1)
bad = 0
by_size = {}
for group, size in zip(groups, sizes):
    members = sorted(group["first"])
    if members != list(range(1, size + 1)):
        print(f"a group move of {size} hands put position writes for hands {members} on the bus")
        bad += 1
        continue
    times = group["first"].values()
    by_size.setdefault(size, []).append((max(times) - min(times)) * 1e6)
frame_us = 111 / 1_000_000 * 1e6  # one 8-byte frame on a 1 Mbit/s line
for size, skews in sorted(by_size.items()):
    floor = (size - 1) * frame_us + 200
    print(f"group of {size} on vcan: skew p50 {statistics.median(skews):.0f} us, "
          f"max {max(skews):.0f} us over {len(skews)} groups "
          f"(floor of a 1 Mbit/s line: {floor:.0f} us)")
sys.exit(1 if bad else 0)
PY
echo "group_skew_kernel: ok"
