#!/usr/bin/env bash
# The README's first command: install, build, and run the whole system on the
# simulator, with no hardware.
#
# Starts dh3-service with three simulated hands (CAN IDs 1, 2, 3 on bus "bus0"
# of service "dh3", the default name; an object sits between the fingers of hand 2 at 40 %).
#  - When dh3ctl is part of the build, a short scripted session lists the
#    hands, initializes them, moves, rotates and grasps, and shows status and
#    the events as they arrive; then the service is stopped (SIGINT) and
#    publishes its hands offline.
#  - When dh3-web is part of the build, it serves the web console and the HTTP
#    API on http://127.0.0.1:${DH3_DEMO_WEB_PORT:-8080}/ during the session (its
#    address and a fresh bearer token are printed); on a terminal, the service
#    and dh3-web then keep running until Enter or Ctrl-C.
#  - Without dh3ctl, the service runs in the foreground and prints its log (hands
#    coming online, every command it serves) until Ctrl-C.
#
#   deploy/run-demo.sh       BUILD_DIR (default build), JOBS (default 2) and
#                            DH3_DEMO_DOMAIN (DDS domain, default 0) may be set
set -euo pipefail
cd "$(dirname "$0")/.."
build=${BUILD_DIR:-build}
jobs=${JOBS:-2}
domain=${DH3_DEMO_DOMAIN:-0}
web_port=${DH3_DEMO_WEB_PORT:-8080}

deploy/install-deps.sh --build   # only what building and running need; the test command installs the test tools
# Release, as tests/run-all.sh builds the same tree (its -O3 warnings are errors there).
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
targets=(dh3-service)
have_ctl=0
# Read whole, not piped into grep -q: an early close would be a SIGPIPE under pipefail.
known_targets=$(cmake --build "$build" --target help)
if grep -q '^dh3ctl:' <<<"$known_targets"; then
  targets+=(dh3ctl)
  have_ctl=1
fi
have_web=0
if grep -q '^dh3-web:' <<<"$known_targets"; then
  targets+=(dh3-web)
  have_web=1
fi
cmake --build "$build" -j "$jobs" --target "${targets[@]}"

service="$build/service/app/dh3-service/dh3-service"
config=$(mktemp --suffix=.yaml)
log=$(mktemp)
web_log=$(mktemp)
token_file=$(mktemp)
service_pid=
events_pid=
web_pid=
cleanup() {
  if [[ -n $events_pid ]]; then kill -INT "$events_pid" 2>/dev/null || true; fi
  if [[ -n $web_pid ]]; then
    kill -TERM "$web_pid" 2>/dev/null || true
    wait "$web_pid" 2>/dev/null || true
  fi
  if [[ -n $service_pid ]]; then
    kill -INT "$service_pid" 2>/dev/null || true
    wait "$service_pid" 2>/dev/null || true
  fi
  rm -f "$config" "$log" "$web_log" "$token_file"
}
trap cleanup EXIT

# The same setup as `dh3-service --bus sim:1,2,3`, plus names and an
# object for hand 2, which only the config file can give.
cat >"$config" <<EOF
name: dh3
domain: $domain
buses:
  - name: bus0
    spec: sim
    hands:
      - {id: 1, name: left}
      - {id: 2, name: right, object: 40}
      - {id: 3, name: spare}
EOF

say() { printf '\n\033[1m== %s\033[0m\n' "$*"; }

say "dh3-service on the simulator: service 'dh3', DDS domain $domain, bus0 with hands 1, 2, 3"
sed 's/^/  /' "$config"

if ((have_ctl == 0)); then
  say "dh3ctl is not built yet: the service runs in the foreground; Ctrl-C stops it"
  echo "  (every hand comes online at once; with --log-level debug it logs each request)"
  # Ctrl-C reaches the service (same process group): it stops cleanly, then
  # this script removes its files.
  "$service" --config "$config" --log-level info
  exit
fi

ctl=$(find "$build/client" -name dh3ctl -type f -perm -u+x | head -n 1)
"$service" --config "$config" --log-level info >"$log" 2>&1 &
service_pid=$!
# Started once it logs that it serves requests (or gone if it could not start).
for _ in $(seq 200); do
  grep -q "service 'dh3' on DDS domain" "$log" && break
  kill -0 "$service_pid" 2>/dev/null || { cat "$log"; exit 1; }
  sleep 0.05
done

if ((have_web == 1)); then
  # A token of this run only; the page asks for it before it sends commands.
  head -c 18 /dev/urandom | base64 >"$token_file"
  "$build/client/dh3-web" --domain "$domain" --listen "127.0.0.1:$web_port" \
    --token-file "$token_file" >"$web_log" 2>&1 &
  web_pid=$!
  for _ in $(seq 200); do
    grep -q "dh3-web: serving" "$web_log" && break
    kill -0 "$web_pid" 2>/dev/null || break
    sleep 0.05
  done
  if grep -q "dh3-web: serving" "$web_log"; then
    say "dh3-web: the web console and the HTTP API"
    echo "  open http://127.0.0.1:$web_port/ in a browser (on this machine; see docs/user-guide.md: dh3-web)"
    echo "  bearer token for commands: $(cat "$token_file")"
    echo "  e.g. curl http://127.0.0.1:$web_port/api/hands"
  else
    say "dh3-web did not start (port $web_port taken? set DH3_DEMO_WEB_PORT); going on without it"
    sed 's/^/  /' "$web_log"
    web_pid=
  fi
fi

run() {
  printf '$ dh3ctl %s\n' "$*"
  "$ctl" --domain "$domain" --timeout 20 "$@" || echo "  (dh3ctl exit status $?)"
}

say "watching events in the background"
# events_pid is dh3ctl's own (not a pipeline's last command): SIGINT ends it
# cleanly and the unbuffered sed then prints all it got.
"$ctl" --domain "$domain" events > >(sed -u 's/^/  [event] /') &
events_pid=$!

say "the hands the service publishes"
run list
say "initializing every hand at once"
pids=()
for id in 1 2 3; do
  run init "dh3/bus0/$id" &
  pids+=($!)
done
wait "${pids[@]}"
run status
say "moving hand 1 to 30 %, rotating hand 3 to 50 %"
run move dh3/bus0/1 30
run rotate dh3/bus0/3 50
say "grasping with hand 2 (an object at 40 %: GRASPED) and hand 1 (nothing there: MISSED)"
run grasp dh3/bus0/2 60
run grasp dh3/bus0/1 40
run status
say "firmware of hand 1"
run version dh3/bus0/1
if [[ -n $web_pid && -t 0 ]]; then
  say "the service and dh3-web keep running: http://127.0.0.1:$web_port/ (token $(cat "$token_file"))"
  read -r -p "  press Enter to stop them " _ || true
fi
say "stopping the service (SIGINT): it publishes every hand offline before it leaves"
kill -INT "$service_pid"
wait "$service_pid" || true
service_pid=
# The offline events were acknowledged before the service left: the watcher has them.
kill -INT "$events_pid" 2>/dev/null || true
wait "$events_pid" 2>/dev/null || true
events_pid=
say "the service's log"
sed 's/^/  /' "$log" | tail -n 25
