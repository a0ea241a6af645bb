#!/bin/bash
# What the owner liveliness costs at rest (BENCHMARKS.md, "Death detection"):
# one dh3-service on the simulator and CLIENTS `dh3ctl events` watchers on
# loopback (UDP, dh3's default), nothing commanded. tshark captures the
# domain's ports for SECONDS; prints packets and bytes per second of the
# liveliness assertions (RTPS heartbeats with the liveliness flag, each a whole
# UDP datagram on the wire) beside all of the domain's traffic, and the
# service's and one client's CPU over the same time.
# Usage: tests/bench/liveliness-cost.sh [BUILD_DIR] [CLIENTS] [SECONDS] [DOMAIN]
# Needs tshark (Debian's tshark) and the right to capture on lo (root).
set -euo pipefail
build=${1:-build}
clients=${2:-1}
seconds=${3:-20}
domain=${4:-219}
service="$build/service/app/dh3-service/dh3-service"
dh3ctl="$build/client/dh3ctl"
work=$(mktemp -d)
# shellcheck source=../support/processes.sh
source "$(dirname "$0")/../support/processes.sh"

# CPU seconds (user + system) a process used so far.
cpu_seconds() {
  awk -v hz="$(getconf CLK_TCK)" '{ print ($14 + $15) / hz }' "/proc/$1/stat"
}

"$service" --domain "$domain" --bus sim:1,2,3 >"$work/service.log" 2>&1 &
service_pid=$!
pids+=("$service_pid")
until "$dh3ctl" --domain "$domain" --timeout 2 status dh3/bus0/1 >/dev/null 2>&1; do sleep 0.2; done
for _ in $(seq "$clients"); do
  "$dh3ctl" --domain "$domain" events >/dev/null 2>&1 &
  pids+=("$!")
done
client_pid=${pids[1]}
sleep 3  # discovery done: its traffic is not what is measured

# RTPS ports of the domain: 7400 + 250 x domain and the 250 after it.
first_port=$((7400 + 250 * domain))
service_cpu=$(cpu_seconds "$service_pid")
client_cpu=$(cpu_seconds "$client_pid")
tshark -q -i lo -f "udp portrange $first_port-$((first_port + 249))" -a "duration:$seconds" \
  -w "$work/capture.pcapng" 2>"$work/tshark.err"
service_cpu=$(echo "$(cpu_seconds "$service_pid") - $service_cpu" | bc)
client_cpu=$(echo "$(cpu_seconds "$client_pid") - $client_cpu" | bc)

# Packets and bytes (frame length) matching display filter $1, per second.
rate() {
  tshark -r "$work/capture.pcapng" -Y "$1" -T fields -e frame.len 2>/dev/null |
    awk -v s="$seconds" '{ n++; b += $1 } END { printf "%7.1f packets/s %9.0f bytes/s", n / s, b / s }'
}
echo "1 service (3 hands, simulator), $clients client(s) watching events, ${seconds} s at rest, loopback UDP"
echo "  liveliness assertions: $(rate 'rtps.flag.liveliness == 1')"
echo "  all of the domain:     $(rate 'udp')"
awk -v s="$seconds" -v svc="$service_cpu" -v cli="$client_cpu" 'BEGIN {
  printf "  CPU: service %.1f %% of a core, one client %.1f %% of a core\n", 100 * svc / s, 100 * cli / s
}'
