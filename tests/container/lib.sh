# Shared by the container tests (sourced): podman with the repository's
# containers.conf, names unique to this run, cleanup on every exit, and the
# test's verdict. Needs SRC (the source tree) set before sourcing.
#
# The tests run the image deploy/container/build-image.sh made (the test
# container.image builds it first); DH3_IMAGE names it (default dh3:latest).
set -uo pipefail
export CONTAINERS_CONF=${CONTAINERS_CONF:-$SRC/deploy/container/containers.conf}
image=${DH3_IMAGE:-dh3:latest}
run_id=dh3t$$
work=$(mktemp -d)
# A DDS domain of this run's own (the host network is shared with other tests).
domain=$((100 + $$ % 100))
failures=0
fail() { echo "FAILED: $*"; failures=$((failures + 1)); }
ok() { echo "ok: $*"; }
skip() { echo "SKIP: $*"; exit 77; }
finish() {
  if ((failures)); then
    echo "$failures failure(s)"
    exit 1
  fi
  echo "$1: all checks passed"
  exit 0
}

# Containers, networks and processes this run made: removed on any exit.
cleanup_containers=()
cleanup_networks=()
cleanup_pids=()
cleanup_hooks=()
cleanup() {
  local hook pid
  for hook in "${cleanup_hooks[@]}"; do eval "$hook" >/dev/null 2>&1; done
  # --ignore: some are gone already (a test removed them); remove the rest.
  if ((${#cleanup_containers[@]})); then
    podman rm --ignore -f -t 0 "${cleanup_containers[@]}" >/dev/null 2>&1
  fi
  local network
  for network in "${cleanup_networks[@]}"; do
    podman network exists "$network" && podman network rm -f "$network" >/dev/null 2>&1
  done
  for pid in "${cleanup_pids[@]}"; do
    kill "$pid" 2>/dev/null && wait "$pid" 2>/dev/null
  done
  rm -rf "$work"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# Skips (exit 77) with the reason where no container can run here.
require_engine() {
  [[ $(id -u) -eq 0 ]] || skip "needs root (rootful podman; CI runs as root)"
  command -v podman >/dev/null || skip "podman is not installed (deploy/container/build-image.sh installs it)"
  podman info >"$work/info" 2>&1 || skip "podman cannot run here: $(tail -n 1 "$work/info")"
}
require_image() {
  require_engine
  podman image exists "$image" || skip "no image $image (the test container.image builds it)"
}

# container NAME ARGS...: `podman run -d` with this run's name prefix; the
# image's scheduled health check is left off (no systemd to schedule it; the
# tests run it with `podman healthcheck run`). Prints nothing; NAME is
# $run_id-NAME.
container() {
  local name=$run_id-$1
  shift
  cleanup_containers+=("$name")
  podman run -d --name "$name" --health-interval disable "$@" >"$work/run.out" 2>&1 || {
    fail "podman run $name: $(cat "$work/run.out")"
    return 1
  }
}
# client ARGS...: a throw-away container running a client program, output on
# stdout; no health check (the image's is the service's).
client() {
  podman run --rm --no-healthcheck "$@"
}

# wait_for SECONDS COMMAND...: until COMMAND succeeds, polling twice a second.
wait_for() {
  local deadline=$((SECONDS + $1))
  shift
  until "$@"; do
    ((SECONDS < deadline)) || return 1
    sleep 0.5
  done
}
# The container's main process exited; prints its exit code.
exit_code() { podman inspect --format '{{.State.ExitCode}}' "$1"; }
running() { [[ $(podman inspect --format '{{.State.Running}}' "$1" 2>/dev/null) == true ]]; }
logs_have() { podman logs "$1" 2>&1 | grep -q -- "$2"; }

# http_get HOST PORT PATH: the body of an HTTP/1.0 GET (bash's /dev/tcp: no
# curl needed).
http_get() {
  local reply
  exec 3<>"/dev/tcp/$1/$2" || return 1
  printf 'GET %s HTTP/1.0\r\nHost: %s\r\n\r\n' "$3" "$1" >&3
  reply=$(timeout 10 cat <&3)
  exec 3<&-
  [[ $reply == "HTTP/1."?" 200"* ]] || return 1
  printf '%s\n' "${reply#*$'\r\n\r\n'}"
}
# A TCP port on the host's loopback that nothing listens on now.
free_port() {
  local port
  for port in $(shuf -i 20000-60000 -n 50); do
    (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null || { echo "$port"; return; }
  done
  return 1
}
