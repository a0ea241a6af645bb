#!/usr/bin/env bash
# The plant: many dh3-service hosts and client hosts as network namespaces on
# one bridge (link-local addresses, UDP only), with simple discovery or a
# redundant pair of Fast DDS discovery servers; measures what it costs at
# each size and prints the tables (plant_run.py says what one run does).
#
#   tests/scale/plant.sh                                  # 2 services x 8 hands, both setups
#   tests/scale/plant.sh --services 2,4,8,16 --discovery simple,server
#   tests/scale/plant.sh --help                           # every option
#
# BUILD_DIR (or --build) is the build tree with dh3-service, dh3ctl and the
# dh3 Python module (default: build/ of this tree). JSON goes to
# BUILD_DIR/scale/, one file per run; tests/scale/plot.py turns them into
# plots. Needs root (network namespaces) and nft; exits 77 with the reason
# where it cannot run. Whatever it made is removed on every exit.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
build=${BUILD_DIR:-$here/../../build}
args=()
while (($#)); do
  case $1 in
    --build) build=$2; shift 2 ;;
    --build=*) build=${1#--build=}; shift ;;
    *) args+=("$1"); shift ;;
  esac
done

if [[ $(id -u) -ne 0 ]]; then
  echo "SKIP: needs root to create network namespaces"
  exit 77
fi
for tool in ip nft /usr/bin/python3; do
  command -v "$tool" >/dev/null || { echo "SKIP: $tool is not installed"; exit 77; }
done

export PLANT_TAG=pl$$
# A backstop for plant_run.py's own cleanup (a SIGKILL, a crash): whatever
# still runs in this run's namespaces is this run's, and the namespaces go.
cleanup() {
  local ns
  for ns in $(ip netns list | awk -v t="$PLANT_TAG-" 'index($1, t) == 1 {print $1}'); do
    ip netns pids "$ns" 2>/dev/null | xargs -r kill -KILL 2>/dev/null || true
    ip netns del "$ns" 2>/dev/null || true
  done
}
trap cleanup EXIT
# The runner in the background, so that a signal reaches this script at once
# (bash runs traps only after a foreground child ends) and is passed on as
# SIGTERM, on which the runner stops its processes and deletes its
# namespaces (a background job of a script ignores SIGINT).
/usr/bin/python3 "$here/plant_run.py" --build "$build" "${args[@]}" &
runner=$!
stop_runner() {
  kill -TERM "$runner" 2>/dev/null || true
  wait "$runner" 2>/dev/null || true
  exit "$1"
}
trap 'stop_runner 130' INT
trap 'stop_runner 143' TERM
wait "$runner"
