#!/usr/bin/env bash
# The shared-memory pitfall of docs/operations.md's deployment section, with two real
# containers of the image on the host's network (traffic kept on loopback):
# dh3-service and a dh3ctl client that both ask for Fast DDS's shared memory
# (--shared-memory), each with its own IPC namespace (podman's default, so its
# own /dev/shm). Fast DDS takes them to be on one host (same addresses) and
# sends the data through shared memory the other cannot see: no status ever
# arrives. `--ipc=host` for both is the way out; dh3's default transports (UDP)
# never meet the pitfall.
#
#   test_shm_pitfall.sh SOURCE_DIR
# Exit 77 (skipped) with the reason where no container engine can run.
SRC=$1
source "$(dirname "$0")/lib.sh"
require_image

serve() {  # serve LABEL PODMAN_OPTION... -- SERVICE_OPTION...
  local label=$1
  shift
  local podman_args=()
  while [[ $1 != -- ]]; do podman_args+=("$1"); shift; done
  shift
  container "$label" --network=host "${podman_args[@]}" "$image" \
    --name shm --domain "$domain" --bus sim:1 --interface 127.0.0.1 "$@"
}
status() {  # status TIMEOUT PODMAN_OPTION...: dh3ctl's status of the hand, in a new container
  local timeout=$1
  shift
  client --network=host "$@" --entrypoint dh3ctl "$image" --domain "$domain" --interface 127.0.0.1 \
    "${ctl_transport[@]}" --timeout "$timeout" status shm/bus0/1 >"$work/ctl.out" 2>&1
}
stop() { podman stop -t 30 "$run_id-$1" >/dev/null 2>&1; }

ctl_transport=(--shared-memory)
echo "== shared memory on, private IPC for each container"
serve private -- --shared-memory || finish "shm pitfall"
if status 15; then
  fail "private IPC, shared memory on: the client got the status (the pitfall is gone?)"
  sed 's/^/  /' "$work/ctl.out"
else
  ok "private IPC, shared memory on: no status ($(tail -n 1 "$work/ctl.out"))"
fi
stop private

echo "== shared memory on, --ipc=host for both"
serve ipc-host --ipc=host -- --shared-memory || finish "shm pitfall"
if status 30 --ipc=host; then
  ok "--ipc=host: the client gets the status"
else
  fail "--ipc=host: no status"; sed 's/^/  /' "$work/ctl.out"
fi
stop ipc-host

ctl_transport=()
echo "== the default transports (UDP only), private IPC"
serve default -- || finish "shm pitfall"
if status 30; then
  ok "default transports: the client (private IPC) gets the status"
else
  fail "default transports: no status"; sed 's/^/  /' "$work/ctl.out"
fi
stop default
finish "shm pitfall"
