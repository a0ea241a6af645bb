#!/usr/bin/env bash
# deploy/systemd/dh3.service: passes `systemd-analyze verify` with no
# warning, keeps its hardening (`systemd-analyze security` exposure), has what
# the issue asks for (memory and task limits, a system-call filter), and
# dh3-service serves requests under its RestrictAddressFamilies= and the
# system calls its SystemCallFilter=~ denies (both emulated with seccomp by
# restrict_af, as systemd does it: other families fail with EAFNOSUPPORT,
# denied calls with EPERM). The unit under a real systemd, its allow list
# (@system-service) included, as the Debian package installs it:
# tests/package/test_install.sh.
#
# deploy/systemd/dh3-web.service too: verify, exposure, limits, an IP address
# allow list of loopback, and dh3-web serving the hands over HTTP under its
# RestrictAddressFamilies= and denied system calls.
#
# And the hot-standby pair as two units run it (role auto, docs/hot-standby.md),
# under dh3.service's restrictions on dh3-sim's shared box: one member serves,
# the other stands by, and takes the hand over when the first is killed.
#
#   test_systemd_unit.sh SOURCE_DIR DH3_SERVICE DH3CTL RESTRICT_AF DH3_WEB DH3_SIM
set -uo pipefail
src=$1 service_bin=$(realpath "$2") ctl_bin=$3 restrict=$4 web_bin=$(realpath "$5") sim_bin=$6
unit=$src/deploy/systemd/dh3.service
work=$(mktemp -d)
service_pid=
web_pid=
pair_pids=()
cleanup() {
  [[ -n $service_pid ]] && kill "$service_pid" 2>/dev/null && wait "$service_pid" 2>/dev/null
  [[ -n $web_pid ]] && kill "$web_pid" 2>/dev/null && wait "$web_pid" 2>/dev/null
  for pid in "${pair_pids[@]}"; do kill -KILL "$pid" 2>/dev/null && wait "$pid" 2>/dev/null; done
  rm -rf "$work"
}
trap cleanup EXIT
failures=0
fail() { echo "FAILED: $*"; failures=$((failures + 1)); }
ok() { echo "ok: $*"; }

# check_unit UNIT_FILE PROGRAM BUILT: `systemd-analyze verify` with no warning
# and an exposure (0 fully locked down to 10) at or below 2.5, of a copy whose
# ExecStart starts BUILT (verify checks that the program exists).
check_unit() {
  local file=$1 program=$2 built=$3 name
  name=$(basename "$file")
  sed "s|^ExecStart=/usr/local/bin/$program |ExecStart=$built |" "$file" >"$work/$name"
  grep -q "^ExecStart=$built " "$work/$name" ||
    fail "$name: ExecStart does not start /usr/local/bin/$program"
  if systemd-analyze verify "$work/$name" >"$work/verify" 2>&1 && [[ ! -s $work/verify ]]; then
    ok "$name: systemd-analyze verify: no errors, no warnings"
  else
    fail "$name: systemd-analyze verify:"
    sed 's/^/  /' "$work/verify"
  fi
  if systemd-analyze security --offline=yes --threshold=25 "$work/$name" >"$work/security" 2>&1; then
    ok "$name: systemd-analyze security: $(grep -o 'Overall exposure level.*' "$work/security")"
  else
    fail "$name: exposure above 2.5: $(grep -o 'Overall exposure level.*' "$work/security")"
  fi
}
check_unit "$unit" dh3-service "$service_bin"

value() { sed -n "s/^$1=//p" "$unit" | tail -n 1; }

# denied_syscalls UNIT_FILE: the x86-64 numbers of the system calls the unit's
# SystemCallFilter=~ lines deny, groups expanded, comma-separated.
unistd=/usr/include/x86_64-linux-gnu/asm/unistd_64.h
expand_syscalls() {
  local entry
  for entry in "$@"; do
    if [[ $entry == @* ]]; then
      expand_syscalls $(systemd-analyze syscall-filter "$entry" | sed -e 1d -e '/^ *#/d')
    else
      echo "$entry"
    fi
  done
}
denied_syscalls() {
  local name numbers=()
  for name in $(expand_syscalls $(sed -n 's/^SystemCallFilter=~//p' "$1") | sort -u); do
    numbers+=($(sed -n "s/^#define __NR_$name \([0-9]*\)$/\1/p" "$unistd"))
  done
  local IFS=,
  echo "${numbers[*]}"
}
# check_limits UNIT_FILE: the memory and task limits and the deny list are there.
check_limits() {
  local file=$1 name
  name=$(basename "$file")
  for setting in MemoryMax TasksMax; do
    grep -qE "^$setting=[0-9]+[KMG]?$" "$file" && ok "$name: $(grep "^$setting=" "$file")" ||
      fail "$name: no $setting="
  done
  grep -qx "SystemCallFilter=@system-service" "$file" && ok "$name: SystemCallFilter=@system-service" ||
    fail "$name: no SystemCallFilter=@system-service"
  local deny
  deny=$(sed -n 's/^SystemCallFilter=~//p' "$file")
  [[ " $deny " == *" @privileged "* && " $deny " == *" @resources "* ]] &&
    ok "$name: SystemCallFilter=~$deny" || fail "$name: SystemCallFilter=~ lacks @privileged or @resources"
}
[[ -r $unistd ]] || fail "no $unistd: cannot name the system calls the units deny"
check_limits "$unit"
denied=$(denied_syscalls "$unit")
# The emulated deny list bites: chown(2) is one of @privileged's.
touch "$work/owned"
if "$restrict" AF_UNIX --deny-syscalls "$denied" -- chown "$(id -u)" "$work/owned" 2>/dev/null; then
  fail "chown succeeded under dh3.service's denied system calls: the emulation does not bite"
else
  ok "chown fails under dh3.service's denied system calls ($(tr -cd , <<<"$denied" | wc -c) + 1 numbers)"
fi
[[ $(value User) =~ ^[a-z][a-z0-9_-]*$ && $(value User) != root ]] && ok "User=$(value User)" ||
  fail "no dedicated User="
for setting in ProtectSystem=strict NoNewPrivileges=yes Restart=on-failure; do
  grep -qx "$setting" "$unit" && ok "$setting" || fail "missing $setting"
done
families=$(value RestrictAddressFamilies)
for family in AF_CAN AF_INET AF_UNIX; do
  [[ " $families " == *" $family "* ]] || fail "RestrictAddressFamilies lacks $family"
done
for family in $families; do
  case $family in AF_CAN | AF_INET | AF_UNIX | AF_NETLINK) ;; *) fail "RestrictAddressFamilies allows $family" ;; esac
done

# The service under the unit's address families, and under those minus
# AF_NETLINK (the reason the unit has it).
# A domain of its own (sets $domain): other tests run beside it.
# shellcheck source=../support/test_domain.sh
source "$(dirname "$0")/../support/test_domain.sh"
serve() {  # serve FAMILIES: start dh3-service restricted to them and the unit's system calls
  "$restrict" "$1" --deny-syscalls "$denied" -- "$service_bin" --name unit --domain "$domain" --bus sim:1 \
    --interface 127.0.0.1 --log-level info >"$work/service.log" 2>&1 &
  service_pid=$!
}
stop() {
  kill -TERM "$service_pid" 2>/dev/null
  wait "$service_pid"
  local status=$?
  service_pid=
  return "$status"
}
ctl() { "$ctl_bin" --domain "$domain" --interface 127.0.0.1 "$@"; }

serve "${families// /,}"
if ctl --timeout 20 status unit/bus0/1 >"$work/ctl" 2>&1; then
  ok "dh3-service answers under RestrictAddressFamilies=$families and its denied system calls"
else
  fail "dh3-service does not answer under RestrictAddressFamilies=$families and its denied system calls"
  sed 's/^/  /' "$work/ctl" "$work/service.log"
fi
stop && ok "dh3-service stops cleanly on SIGTERM (exit 0)" || fail "dh3-service exit status $? on SIGTERM"

without=${families/AF_NETLINK/}
without=$(echo $without)
serve "${without// /,}"
if ctl --timeout 5 status unit/bus0/1 >"$work/ctl" 2>&1; then
  echo "NOTE: dh3-service now works without AF_NETLINK; the unit could drop it"
else
  ok "without AF_NETLINK the service is not reachable (getifaddrs needs netlink): the unit needs it"
fi
stop

# dh3-web.service: the same checks for the web console's unit.
web_unit=$src/deploy/systemd/dh3-web.service
check_unit "$web_unit" dh3-web "$web_bin"
grep -qx "ExecStart=$web_bin --listen 127.0.0.1:8080 --token-file /etc/dh3/web.token" "$work/dh3-web.service" &&
  ok "dh3-web.service listens on loopback and takes the token from /etc/dh3/web.token" ||
  fail "dh3-web.service: ExecStart is not loopback with /etc/dh3/web.token"
grep -qx "User=dh3-web" "$web_unit" && ok "dh3-web.service: User=dh3-web" || fail "dh3-web.service: no User=dh3-web"
check_limits "$web_unit"
grep -qx "IPAddressDeny=any" "$web_unit" && grep -qx "IPAddressAllow=localhost multicast" "$web_unit" &&
  ok "dh3-web.service: IPAddressDeny=any, IPAddressAllow=localhost multicast (loopback and DDS discovery)" ||
  fail "dh3-web.service: no IP address allow list of loopback (and multicast for discovery)"
web_families=$(sed -n 's/^RestrictAddressFamilies=//p' "$web_unit" | tail -n 1)
web_denied=$(denied_syscalls "$web_unit")
serve "${families// /,}"
"$restrict" "${web_families// /,}" --deny-syscalls "$web_denied" -- "$web_bin" --domain "$domain" --listen 127.0.0.1:0 \
  --log-level warn >"$work/web.log" 2>&1 &
web_pid=$!
hands=
for _ in $(seq 200); do
  port=$(grep -o 'serving http://127.0.0.1:[0-9]*' "$work/web.log" | grep -o '[0-9]*$')
  if [[ -n $port ]] && exec 3<>"/dev/tcp/127.0.0.1/$port"; then
    printf 'GET /api/hands HTTP/1.0\r\n\r\n' >&3
    hands=$(cat <&3)
    exec 3<&-
    [[ $hands == *'"hand":"unit/bus0/1"'* ]] && break
  fi
  sleep 0.1
done
[[ $hands == *'"hand":"unit/bus0/1"'* ]] &&
  ok "dh3-web serves the hands under RestrictAddressFamilies=$web_families and its denied system calls" ||
  { fail "dh3-web does not serve hand unit/bus0/1 under RestrictAddressFamilies=$web_families"; sed 's/^/  /' "$work/web.log"; }
kill -TERM "$web_pid" && wait "$web_pid" && ok "dh3-web stops cleanly on SIGTERM (exit 0)" ||
  fail "dh3-web exit status $? on SIGTERM"
web_pid=
stop

# The pair: two members of role auto under dh3.service's address families and
# denied system calls, the way two cell PCs run the unit, on a shared box.
# log_has FILE TEXT: waits up to 30 s for TEXT in FILE.
log_has() {
  local i
  for i in $(seq 300); do grep -q "$2" "$1" 2>/dev/null && return 0; sleep 0.1; done
  return 1
}
"$sim_bin" --listen 127.0.0.1:0 --hands 1 --shared --log-level warn >"$work/sim.out" 2>"$work/sim.log" &
pair_pids+=($!)
log_has "$work/sim.out" "^listening " || fail "dh3-sim did not say where it listens"
box=$(sed -n 's/^listening //p' "$work/sim.out")
printf 'name: pair\nrole: auto\nbuses:\n  - name: bus0\n    spec: tcp:%s\n    hands: [{id: 1}]\n' \
  "$box" >"$work/pair.yaml"
member() {  # member N: a pair member, its log in member-N.log
  "$restrict" "${families// /,}" --deny-syscalls "$denied" -- "$service_bin" --config "$work/pair.yaml" \
    --domain "$domain" --interface 127.0.0.1 >"$work/member-$1.log" 2>&1 &
  pair_pids+=($!)
}
member 1
first=${pair_pids[-1]}
log_has "$work/member-1.log" "took the cell" && ok "pair: the first member serves the cell nobody served" ||
  fail "pair: the first member never took the cell"
member 2
second=${pair_pids[-1]}
log_has "$work/member-2.log" "is served by" && ok "pair: the second member stands by for it" ||
  fail "pair: the second member never stood by"
kill -KILL "$first" && wait "$first" 2>/dev/null
log_has "$work/member-2.log" "took over from" && ok "pair: the first member killed, the second takes over" ||
  fail "pair: the second member never took over"
if ctl --timeout 20 status pair/bus0/1 >"$work/ctl" 2>&1; then
  ok "pair: the hand answers through the member that took over"
else
  fail "pair: the hand does not answer after the takeover"
  sed 's/^/  /' "$work/ctl" "$work/member-1.log" "$work/member-2.log"
fi
kill -TERM "$second" && wait "$second" && ok "pair: the serving member stops cleanly on SIGTERM (exit 0)" ||
  fail "pair: the serving member's exit status $? on SIGTERM"

if ((failures)); then
  echo "$failures failure(s)"
  exit 1
fi
echo "systemd unit: all checks passed"
