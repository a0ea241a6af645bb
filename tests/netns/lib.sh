# What every netns script needs: test hosts as network namespaces joined by
# veth pairs with link-local addresses, a visible skip where they cannot be
# made, and teardown of everything made. Sourced, not run.
#
#   source "$(dirname "$0")/lib.sh"       # sets domain (the script's own DDS domain)
#                                         # and work (a scratch folder, removed at exit)
#   show_logs() { ...; }                  # optional: what fail() prints after its reason
#   on_exit() { ...; }                    # optional: stops the script's processes
#   require_namespaces                    # skips (exit 77) without root or iproute2
#   add_hosts NS...                       # skips if the first cannot be made
#   link NS_A ADDR_A NS_B ADDR_B NAME     # veth NAMEa in NS_A, NAMEb in NS_B, /24, up
#   stop_process PID                      # SIGTERM, then wait for it
#   step DESCRIPTION COMMAND...           # says what it does; fails if COMMAND does

netns_hosts=()
# A domain per run, so that parallel tests do not meet.
domain=$((10 + $$ % 200))
work=$(mktemp -d)

skip() {
  echo "SKIP: $*"
  exit 77
}

fail() {
  echo "FAILED: $*"
  declare -F show_logs >/dev/null && show_logs
  exit 1
}

netns_cleanup() {
  declare -F on_exit >/dev/null && on_exit
  for ns in "${netns_hosts[@]}"; do ip netns del "$ns" 2>/dev/null; done
  rm -rf "$work"
}
trap netns_cleanup EXIT

require_namespaces() {
  [[ $(id -u) -eq 0 ]] || skip "needs root to create network namespaces"
  command -v ip >/dev/null || skip "iproute2 (ip) is not installed"
}

add_hosts() {
  local err
  err=$(ip netns add "$1" 2>&1) || skip "ip netns add failed: $err"
  netns_hosts+=("$1")
  shift
  for ns in "$@"; do
    ip netns add "$ns" || fail "could not create namespace $ns"
    netns_hosts+=("$ns")
  done
  for ns in "${netns_hosts[@]}"; do ip -n "$ns" link set lo up; done
}

link() {
  ip link add "$5a" type veth peer name "$5b" || fail "veth $5 failed"
  ip link set "$5a" netns "$1" && ip link set "$5b" netns "$3"
  ip -n "$1" addr add "$2/24" dev "$5a" && ip -n "$3" addr add "$4/24" dev "$5b"
  ip -n "$1" link set "$5a" up multicast on && ip -n "$3" link set "$5b" up multicast on
}

stop_process() {
  [[ -n ${1:-} ]] || return 0
  kill -TERM "$1" 2>/dev/null
  wait "$1" 2>/dev/null
  return 0
}

step() {
  local what=$1
  shift
  echo "== $what"
  "$@" || fail "$what"
}
