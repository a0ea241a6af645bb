#!/usr/bin/env bash
# Runs the health checks of running podman containers every INTERVAL seconds
# (default 10) until stopped: what systemd's timers do for podman on a
# systemd host. Without systemd (as on dh3's build machines) podman never runs
# a HEALTHCHECK by itself, so a container stays "starting" and a Compose
# `depends_on: condition: service_healthy` waits forever. Run this beside
# `docker-compose up` there:
#
#   deploy/container/run-healthchecks.sh [--project NAME] [INTERVAL] &
#
# --project NAME: only the containers of that Compose project (its label
# com.docker.compose.project). Containers without a health check are skipped.
# Uses deploy/container/containers.conf unless CONTAINERS_CONF is set.
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd -P)
export CONTAINERS_CONF=${CONTAINERS_CONF:-$here/containers.conf}
filter=()
if [[ ${1:-} == --project ]]; then
  filter=(--filter "label=com.docker.compose.project=$2")
  shift 2
fi
interval=${1:-10}
trap 'exit 0' TERM INT
while :; do
  for id in $(podman ps -q "${filter[@]}"); do
    # Only containers that have one: the check's own status says how it went.
    if [[ -n $(podman inspect --format '{{if .Config.Healthcheck}}yes{{end}}' "$id" 2>/dev/null) ]]; then
      podman healthcheck run "$id" >/dev/null 2>&1
    fi
  done
  sleep "$interval" &
  wait $!
done
