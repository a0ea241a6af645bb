# What the kernel test scripts (end_to_end.sh, record_kernel.sh,
# group_skew_kernel.sh) share, sourced after `build` is set:
#   kernel_script_setup NAME   the programs ($sim, $service, $ctl_bin), a work
#                              folder $work, a DDS $domain of its own, $pids to
#                              kill on exit; a function extra_cleanup, if the
#                              script defines one, runs on exit too
#   fail MESSAGE               says why, prints the programs' logs, exits 1
#   wait_for FILE PATTERN SECONDS
#   stop_service PID           SIGTERM to dh3-service; fails unless it exits 0
kernel_script_setup() {
  sim=$build/service/app/dh3-sim/dh3-sim
  service=$build/service/app/dh3-service/dh3-service
  ctl_bin=$build/client/dh3ctl
  work=$(mktemp -d "/tmp/dh3-$1.XXXXXX")
  domain=$((100 + RANDOM % 100))
  # shellcheck source=../support/processes.sh
  source "$(dirname "${BASH_SOURCE[0]}")/../support/processes.sh"
}

fail() {
  echo "FAIL: $*"
  for f in service.log sim.out sim.err; do
    [[ -f $work/$f ]] && { echo "---- $f (last 30 lines)"; tail -n 30 "$work/$f"; }
  done
  exit 1
}

wait_for() {  # wait_for FILE PATTERN SECONDS
  for _ in $(seq $(($3 * 20))); do
    grep -q -- "$2" "$1" 2>/dev/null && return 0
    sleep 0.05
  done
  return 1
}

stop_service() {
  kill -TERM "$1"
  local status=0
  wait "$1" || status=$?
  ((status == 0)) || fail "dh3-service exited $status on SIGTERM"
}
