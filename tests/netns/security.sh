#!/usr/bin/env bash
# DDS Security between real hosts: dh3-service in one network namespace, its
# clients in another, joined by a veth pair (link-local addresses, UDP only).
# The credentials come from deploy/security/make-test-pki.sh; the clients use
# deploy/dds/secure.xml's profiles (with the test PKI's paths).
#
# 0. Control: without security, a capture of the UDP payloads on the
#    service's link holds a hand's name in plain text (the capture works), and
#    the service warned once at start that anyone on that network can drive
#    every hand; the secure service does not warn.
# 1. The operator drives a hand; its CAN ID change is refused (its
#    permissions do not grant the admin request topic), the admin's, through
#    secure.xml's dh3_admin_secure, is taken (the service allows admin).
# 2. The monitor sees the hands' status, but its command never reaches the
#    service: the hand does not move, and the monitor gets an error or a
#    timeout of its own, promptly (no hang).
# 3. A participant without credentials sees nothing and moves nothing.
# 4. Everything the secure participants sent is encrypted: the capture of the
#    UDP payloads does not hold the hand's name.
#
#   security.sh SOURCE_DIR DH3_SERVICE DH3CTL
# Exit 77 (ctest: skipped) with the reason when namespaces cannot be made.
set -uo pipefail
src=$1 service_bin=$2 ctl_bin=$3

source "$(dirname "$0")/lib.sh"
tag=sec$$
srv=$tag-srv cli=$tag-cli
srv_addr=169.254.50.1 cli_addr=169.254.50.2
dev=s${$}a  # the service's end of the link, where the capture listens
# A hand name that appears nowhere but in the samples the service publishes
# (status and service info), never in discovery's plain participant data.
marker=zq7handmarker$$
service_pid=
capture_pid=

stop_service() {
  stop_process "$service_pid"
  service_pid=
}
on_exit() {
  stop_service
  stop_process "$capture_pid"
}
show_logs() {
  echo "--- dh3-service log"; tail -n 30 "$work/service.log" 2>/dev/null
}

require_namespaces
command -v python3 >/dev/null || fail "python3 is needed for the packet capture"
service_secure=(--security-dir "$work/pki" --security-identity service)

"$src/deploy/security/make-test-pki.sh" --domains "$domain" "$work/pki" >/dev/null || fail "make-test-pki.sh failed"
sed "s|file:///etc/dh3/pki/|file://$work/pki/|g" "$src/deploy/dds/secure.xml" >"$work/secure.xml"

add_hosts "$srv" "$cli"
link "$srv" "$srv_addr" "$cli" "$cli_addr" "s${$}"

cat >"$work/config.yaml" <<EOF
name: cell
allow_admin: true
buses:
  - name: bus0
    spec: sim
    hands:
      - {id: 1, name: $marker}
      - {id: 2}
EOF

# UDP payloads seen on the service's link: counts, and whether the marker was
# in any. Prints "ready" once capturing, the summary on SIGTERM.
cat >"$work/capture.py" <<'EOF'
import signal, socket, struct, sys
dev, marker = sys.argv[1], sys.argv[2].encode()
s = socket.socket(socket.AF_PACKET, socket.SOCK_RAW, socket.ntohs(0x0003))
s.bind((dev, 0))
s.settimeout(0.2)
stop = []
signal.signal(signal.SIGTERM, lambda *_: stop.append(1))
packets = payload_bytes = found = 0
print("ready", flush=True)
while not stop:
    try:
        frame = s.recv(65536)
    except (socket.timeout, InterruptedError):
        continue
    if len(frame) < 34 or frame[12:14] != b"\x08\x00" or frame[23] != 17:
        continue
    ihl = (frame[14] & 0x0F) * 4
    payload = frame[14 + ihl + 8:]
    packets += 1
    payload_bytes += len(payload)
    found += marker in payload
print(f"packets {packets} bytes {payload_bytes} marker {found}", flush=True)
EOF
capture_start() {
  ip netns exec "$srv" python3 "$work/capture.py" "$dev" "$marker" >"$work/capture.out" 2>&1 &
  capture_pid=$!
  for _ in $(seq 200); do
    grep -q ready "$work/capture.out" && return 0
    kill -0 "$capture_pid" 2>/dev/null || break
    sleep 0.05
  done
  cat "$work/capture.out"
  fail "the packet capture did not start"
}
capture_stop() {  # sets packets and found
  kill -TERM "$capture_pid"
  wait "$capture_pid"
  capture_pid=
  read -r _ packets _ _ _ found < <(grep '^packets ' "$work/capture.out")
  [[ -n ${packets:-} ]] || { cat "$work/capture.out"; fail "no capture summary"; }
}

start_service() {  # start_service [OPTIONS...]
  ip netns exec "$srv" "$service_bin" --config "$work/config.yaml" --domain "$domain" \
    --interface "$srv_addr" --udp-only --log-level info "$@" >"$work/service.log" 2>&1 &
  service_pid=$!
}
# Clients: the operator, the admin and the monitor through secure.xml's
# profiles; the outsider with no credentials at all.
operator() {
  ip netns exec "$cli" "$ctl_bin" --domain "$domain" --xml "$work/secure.xml" \
    --profile dh3_operator_secure "$@"
}
admin() {
  ip netns exec "$cli" "$ctl_bin" --domain "$domain" --xml "$work/secure.xml" \
    --profile dh3_admin_secure "$@"
}
monitor() {
  ip netns exec "$cli" "$ctl_bin" --domain "$domain" --xml "$work/secure.xml" \
    --profile dh3_monitor_secure "$@"
}
outsider() {
  ip netns exec "$cli" "$ctl_bin" --domain "$domain" --interface "$cli_addr" --udp-only "$@"
}
exposure_warnings() {  # in the last service's log
  grep -c "DDS Security is off and this service is reachable from other machines: anyone on that network can drive every hand" \
    "$work/service.log"
}
position_of_hand_1() {  # as the operator sees it
  operator --timeout 20 --json status cell/bus0/1 | sed -n 's/.*"position":\(-\{0,1\}[0-9]*\).*/\1/p'
}

echo "== control: without security the hand's name crosses the link in plain text"
capture_start
start_service
outsider --timeout 20 status cell/bus0/1 || fail "control: the plain client cannot reach the plain service"
stop_service
capture_stop
echo "   $packets UDP packets, marker in $found"
((found > 0)) || fail "control: the capture did not see the hand's name in plain text"
warned=$(exposure_warnings)
((warned == 1)) || { show_logs; fail "control: the plain service on $srv_addr warned $warned times (expected once) that anyone on that network can drive every hand"; }
echo "   the plain service warned once at start: anyone on that network can drive every hand"

echo "== secure service (${service_secure[*]})"
capture_start
start_service "${service_secure[@]}"

echo "== 1. the operator drives hand 1"
operator --timeout 20 list || fail "the operator does not see the service"
operator --timeout 20 init cell/bus0/1 || fail "the operator cannot initialize hand 1"
operator --timeout 20 move cell/bus0/1 30 || fail "the operator cannot move hand 1"
# The move is answered when the hand echoes it; the fingers then need time.
arrived=0
for _ in $(seq 1 100); do
  [[ $(position_of_hand_1) == 30 ]] && { arrived=1; break; }
  sleep 0.2
done
((arrived)) || fail "hand 1 did not reach 30 after the operator's move"

echo "== 1b. only the admin changes a CAN ID"
if operator --timeout 10 set-can-id cell/bus0/2 9 --yes >"$work/operator-admin.out" 2>&1; then
  cat "$work/operator-admin.out"
  fail "the operator changed hand 2's CAN ID"
fi
grep -q "not permitted to publish administrative requests" "$work/operator-admin.out" ||
  { cat "$work/operator-admin.out"; fail "the operator's CAN ID change failed for another reason"; }
echo "   the operator's refused: not permitted to publish administrative requests"
admin --timeout 20 set-can-id cell/bus0/2 9 --yes >"$work/admin.out" 2>&1 ||
  { cat "$work/admin.out"; show_logs; fail "the admin (dh3_admin_secure) cannot change hand 2's CAN ID"; }
echo "   the admin's taken: $(head -n 1 "$work/admin.out")"

echo "== 2. the monitor sees status but cannot command"
monitor --timeout 20 --json status cell/bus0/1 >"$work/monitor.json" 2>"$work/monitor.err" ||
  { cat "$work/monitor.err"; fail "the monitor does not see hand 1's status"; }
grep -q '"position":30' "$work/monitor.json" || { cat "$work/monitor.json"; fail "the monitor sees a wrong status"; }
echo "   monitor sees hand 1 at 30"
# Its own --timeout bounds the wait; `timeout` catches a hang (exit 124).
timeout 60 ip netns exec "$cli" "$ctl_bin" --domain "$domain" --xml "$work/secure.xml" \
  --profile dh3_monitor_secure --timeout 10 move cell/bus0/1 80 >"$work/monitor.out" 2>&1
status=$?
cat "$work/monitor.out"
((status == 124)) && fail "the monitor's move hung"
((status == 0)) && fail "the monitor's move succeeded"
[[ -s $work/monitor.out ]] || fail "the monitor's move failed without a message"
[[ $(position_of_hand_1) == 30 ]] || fail "hand 1 moved on the monitor's command"
echo "   refused (exit $status); hand 1 still at 30"

echo "== 3. a participant without credentials sees nothing"
if outsider --timeout 8 list >"$work/outsider.out" 2>&1; then
  cat "$work/outsider.out"
  fail "the outsider sees the secure service"
fi
grep -q NO_SERVICE "$work/outsider.out" || { cat "$work/outsider.out"; fail "expected NO_SERVICE"; }
outsider --timeout 5 move cell/bus0/1 80 >/dev/null 2>&1 && fail "the outsider's move succeeded"
[[ $(position_of_hand_1) == 30 ]] || fail "hand 1 moved on the outsider's command"
echo "   nothing seen; hand 1 still at 30"

stop_service
capture_stop
warned=$(exposure_warnings)
((warned == 0)) || { show_logs; fail "the secure service warned that DDS Security is off"; }
echo "== 4. $packets UDP packets captured on the service's link, marker in $found"
((packets > 20)) || fail "too little traffic captured to judge"
((found == 0)) || fail "the hand's name crossed the link in plain text $found time(s)"

echo "security: all steps passed"
