#!/usr/bin/env bash
# Figures of the dh3 image (BENCHMARKS.md, "Container image"), printed, not
# judged:
#   - the image's size, its base's, and what dh3's own files take in it;
#   - time from `podman run` to the service's first hand online (the
#     service's own log line; RUNS runs, default 5), and to the health check's
#     first pass;
#   - the service's memory inside the container, idle and after a pick loop:
#     its VmRSS and the container's cgroup memory (what `podman stats` shows).
#
#   deploy/container/measure.sh [IMAGE]      (default dh3:latest; build it first
#                                             with deploy/container/build-image.sh)
#
# The containers use the host's network with DDS on loopback only, on a DDS
# domain of their own. Runs as root; uses deploy/container/containers.conf
# unless CONTAINERS_CONF is set.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd -P)
export CONTAINERS_CONF=${CONTAINERS_CONF:-$here/containers.conf}
image=${1:-dh3:latest}
runs=${RUNS:-5}
domain=$((100 + $$ % 100))
name=dh3-measure-$$
dds=(--domain "$domain" --interface 127.0.0.1)
cleanup() { podman rm --ignore -f -t 0 "$name" >/dev/null 2>&1 || true; }
trap cleanup EXIT
podman image exists "$image" || { echo "measure: no image $image (deploy/container/build-image.sh)" >&2; exit 1; }

mb() { awk -v b="$1" 'BEGIN { printf "%.1f MB", b / 1e6 }'; }
echo "image $image: $(mb "$(podman image inspect --format '{{.Size}}' "$image")")"
if podman image exists debian:bookworm-slim; then
  echo "  base debian:bookworm-slim: $(mb "$(podman image inspect --format '{{.Size}}' debian:bookworm-slim)")"
fi
own=$(podman run --rm --no-healthcheck --entrypoint du "$image" -sb /usr/local /etc/dh3 | awk '{s += $1} END {print s}')
echo "  dh3's own files (/usr/local, /etc/dh3): $(mb "$own")"

# The service's log times are the container's clock, which is the host's.
epoch_of_log() { date -u -d "$(cut -c1-23 <<<"$1")" +%s.%N; }
start_service() {
  podman run -d --name "$name" --network=host --health-interval disable -e DH3_DOMAIN="$domain" \
    -e DH3_HEALTH_INTERFACE=127.0.0.1 "$image" --config /etc/dh3/dh3.yaml "${dds[@]}" \
    --metrics 127.0.0.1:0 >/dev/null
}
online_line() { podman logs "$name" 2>&1 | grep -m1 ': online$'; }

echo "podman run -> first hand online (the service's log), and -> health check passes:"
online_times=()
for ((i = 1; i <= runs; i++)); do
  t0=$(date -u +%s.%N)
  start_service
  until line=$(online_line); do sleep 0.05; done
  t1=$(epoch_of_log "$line")
  until podman healthcheck run "$name" >/dev/null 2>&1; do sleep 0.2; done
  t2=$(date -u +%s.%N)
  online=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.0f", (b - a) * 1000 }')
  healthy=$(awk -v a="$t0" -v b="$t2" 'BEGIN { printf "%.0f", (b - a) * 1000 }')
  online_times+=("$online")
  echo "  run $i: first hand online after $online ms, healthy after $healthy ms"
  if ((i < runs)); then cleanup; fi
done
sorted=$(printf '%s\n' "${online_times[@]}" | sort -n)
echo "  first hand online: median $(sed -n "$(((runs + 1) / 2))p" <<<"$sorted") ms, min $(head -n1 <<<"$sorted") ms, max $(tail -n1 <<<"$sorted") ms"

memory() {
  local pid rss cgroup
  pid=$(podman inspect --format '{{.State.Pid}}' "$name")
  rss=$(awk '/^VmRSS:/ {print $2, $3}' "/proc/$pid/status")
  cgroup=$(podman stats --no-stream --format '{{.MemUsage}}' "$name")
  echo "  $1: dh3-service VmRSS $rss; container memory (podman stats) $cgroup"
}
echo "memory of the service (3 simulated hands):"
memory "idle, health checked"
podman run --rm --no-healthcheck --network=host --entrypoint pick_loop "$image" "${dds[@]}" --udp-only \
  --hand cell/bus0/2 --cycles 20 | tail -n 1 | sed 's/^/  pick_loop: /'
memory "after 20 pick cycles"
