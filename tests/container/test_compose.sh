#!/usr/bin/env bash
# deploy/container/compose.yaml brought up for real with Debian's
# docker-compose 1.29 against podman's Docker API (`podman system service` on
# a unix socket of this test): `up` starts the discovery server and the
# service; the client starts once the service's health check passed (run by
# deploy/container/run-healthchecks.sh: no systemd schedules health checks
# here) and its pick loop succeeds; the metrics port answers on the host;
# `stop` ends every container with exit 0 (the discovery server too); `down`
# removes the containers and the network.
#
#   test_compose.sh SOURCE_DIR
# Exit 77 (skipped) with the reason where no container engine can run.
SRC=$1
source "$(dirname "$0")/lib.sh"
require_image
command -v docker-compose >/dev/null || skip "docker-compose is not installed (deploy/container/build-image.sh installs it)"
compose_file=$SRC/deploy/container/compose.yaml
project=$run_id

# podman's Docker API, for this test only; stopped on every exit.
socket=$work/podman.sock
podman system service --time=0 "unix://$socket" >"$work/service-api.log" 2>&1 &
cleanup_pids+=($!)
export DOCKER_HOST=unix://$socket
wait_for 30 test -S "$socket" || { fail "podman system service made no socket"; cat "$work/service-api.log"; finish compose; }

export DH3_METRICS_PORT
DH3_METRICS_PORT=$(free_port)
export DH3_WEB_PORT
DH3_WEB_PORT=$(free_port)
compose() { timeout 300 docker-compose --no-ansi -p "$project" -f "$compose_file" "$@"; }
cleanup_hooks+=("compose down -t 0")
cleanup_networks+=("${project}_dh3")

# The health checks of this project's containers, every 2 s.
"$SRC/deploy/container/run-healthchecks.sh" --project "$project" 2 &
cleanup_pids+=($!)

echo "== docker-compose up"
compose config -q 2>"$work/config" && ok "docker-compose $(docker-compose version --short) accepts the file" ||
  { fail "docker-compose rejects the file:"; sed 's/^/  /' "$work/config"; finish compose; }
if compose up -d --no-build >"$work/up" 2>&1; then
  ok "up: $(grep -c -i 'done\|started\|healthy' "$work/up") steps"
else
  fail "docker-compose up:"; sed 's/^/  /' "$work/up"
fi
id_of() { compose ps -q "$1" 2>/dev/null; }
service=$(id_of service) pick=$(id_of pick) discovery=$(id_of discovery) web=$(id_of web)
[[ -n $service && -n $pick && -n $discovery && -n $web ]] || { fail "not every container was made"; compose ps; finish compose; }
[[ $(podman inspect --format '{{.State.Health.Status}}' "$service") == healthy ]] &&
  ok "the service is healthy" || fail "the service is not healthy"

exited() { ! running "$pick"; }
if wait_for 120 exited && [[ $(exit_code "$pick") == 0 ]] && podman logs "$pick" 2>&1 | grep -q '^done: 5 cycles, 5 grasped'; then
  ok "the client's pick loop: $(podman logs "$pick" 2>&1 | tail -n 1)"
else
  fail "the client's pick loop (exit $(exit_code "$pick")):"; podman logs "$pick" 2>&1 | sed 's/^/  /'
fi
if http_get 127.0.0.1 "$DH3_METRICS_PORT" /metrics >"$work/metrics" && grep -q '^dh3_hand_online{.*} 1' "$work/metrics"; then
  ok "metrics at 127.0.0.1:$DH3_METRICS_PORT from the host"
else
  fail "no metrics at 127.0.0.1:$DH3_METRICS_PORT"
fi
if http_get 127.0.0.1 "$DH3_WEB_PORT" /api/hands >"$work/hands" && grep -q '"hand":"cell/bus0/2"' "$work/hands"; then
  ok "dh3-web lists the hands at 127.0.0.1:$DH3_WEB_PORT from the host"
else
  fail "dh3-web does not list hand cell/bus0/2 at 127.0.0.1:$DH3_WEB_PORT:"; sed 's/^/  /' "$work/hands"
fi

echo "== docker-compose stop, down"
compose stop -t 30 >"$work/stop" 2>&1 || { fail "docker-compose stop:"; sed 's/^/  /' "$work/stop"; }
for name in discovery service pick web; do
  id=$(id_of "$name")
  code=$(exit_code "$id")
  [[ $code == 0 ]] && ok "$name exited 0" || fail "$name exited $code"
done
podman logs "$service" 2>&1 | grep -q "service 'cell' stopped" && ok "the service stopped in order" ||
  fail "the service's log does not end with its orderly stop"
compose down -t 30 >"$work/down" 2>&1 || { fail "docker-compose down:"; sed 's/^/  /' "$work/down"; }
left=$(podman ps -a -q --filter "label=com.docker.compose.project=$project" | wc -l)
((left == 0)) && ok "down removed every container" || fail "$left containers left after down"
podman network exists "${project}_dh3" && fail "network ${project}_dh3 left after down" ||
  ok "down removed the network"
finish compose
