#!/usr/bin/env bash
# deploy/dds/*.xml load in Fast DDS 2.9 and are what their comments say:
#   udp_only.xml          UDP only, no shared memory, simple discovery
#   discovery_client.xml  discovery CLIENT of server id 0, UDP only
#   secure.xml            PKI-DH, Access-Permissions, AES-GCM-GMAC for service,
#                         operator, admin and monitor, with the permissions
#                         the test PKI grants them (admin requests: the admin
#                         only), UDP only
# Participants are created from every profile where a private network
# namespace can be made (root), so "every interface" is loopback only.
#
#   test_profiles.sh SOURCE_DIR CHECK_PROFILES
set -uo pipefail
src=$1 check=$2
dds=$src/deploy/dds
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failures=0
fail() { echo "FAILED: $*"; failures=$((failures + 1)); }

create=()
# The DDS domain the participants are created on; the test PKI grants it.
domain=7
run_check() {  # run_check FILE PROFILE...: check_profiles' output into $work/out
  if ((${#create[@]})); then
    unshare -n sh -c 'ip link set lo up && exec "$@"' sh "$check" "$@" --create "$domain" >"$work/out" 2>"$work/err"
  else
    "$check" "$@" >"$work/out" 2>"$work/err"
  fi
  local status=$?
  sed 's/^/  /' "$work/out"
  ((status == 0)) || sed 's/^/  /' "$work/err"
  return "$status"
}
# expect SECTION LINE: LINE is in the section of profile SECTION
expect() {
  awk -v p="profile $1" '$0 == p {on = 1; next} /^profile / {on = 0} on' "$work/out" | grep -qxF "$2" ||
    fail "$1: expected \"$2\""
}
expect_not() {
  awk -v p="profile $1" '$0 == p {on = 1; next} /^profile / {on = 0} on' "$work/out" | grep -qxF "$2" &&
    fail "$1: did not expect \"$2\""
}
transports_udp_only() {  # one UDPv4 transport on every interface, nothing else
  expect "$1" "builtin_transports false"
  expect "$1" "transport UDPv4"
  [[ $(awk -v p="profile $1" '$0 == p {on = 1; next} /^profile / {on = 0} on' "$work/out" |
    grep -c '^transport ') == 1 ]] || fail "$1: more than one transport"
}

if [[ $(id -u) -eq 0 ]] && unshare -n true 2>/dev/null; then
  create=(yes)
  echo "participants are created from the profiles (private network namespace)"
else
  echo "NOTE: no private network namespace (needs root): profiles are loaded and inspected, no participant is created"
fi

echo "== udp_only.xml"
run_check "$dds/udp_only.xml" dh3_udp_only || fail "udp_only.xml did not load"
transports_udp_only dh3_udp_only
expect dh3_udp_only "discovery SIMPLE"
((${#create[@]})) && expect dh3_udp_only "participant created"

echo "== discovery_client.xml"
run_check "$dds/discovery_client.xml" dh3_discovery_client || fail "discovery_client.xml did not load"
transports_udp_only dh3_discovery_client
expect dh3_discovery_client "discovery CLIENT"
# Fast DDS's default prefix of server id 0: what `fastdds discovery -i 0` uses.
expect dh3_discovery_client "server 44.53.00.5f.45.50.52.4f.53.49.4d.41 127.0.0.1:11811"
((${#create[@]})) && expect dh3_discovery_client "participant created"

echo "== secure.xml, with a test PKI in place of /etc/dh3/pki"
"$src/deploy/security/make-test-pki.sh" --domains "$domain" "$work/pki" >/dev/null || fail "make-test-pki.sh failed"
sed "s|file:///etc/dh3/pki/|file://$work/pki/|g" "$dds/secure.xml" >"$work/secure.xml"
grep '<value>' "$work/secure.xml" | grep -q '/etc/dh3/pki' &&
  fail "secure.xml has a value naming /etc/dh3/pki other than as file:///etc/dh3/pki/"
run_check "$work/secure.xml" dh3_service_secure dh3_operator_secure dh3_admin_secure \
  dh3_monitor_secure || fail "secure.xml did not load"
for id in service operator admin monitor; do
  p=dh3_${id}_secure
  transports_udp_only "$p"
  expect "$p" "property dds.sec.auth.plugin=builtin.PKI-DH"
  expect "$p" "property dds.sec.access.plugin=builtin.Access-Permissions"
  expect "$p" "property dds.sec.crypto.plugin=builtin.AES-GCM-GMAC"
  expect "$p" "property dds.sec.auth.builtin.PKI-DH.identity_ca=file://$work/pki/identity_ca.pem"
  expect "$p" "property dds.sec.auth.builtin.PKI-DH.identity_certificate=file://$work/pki/$id/cert.pem"
  expect "$p" "property dds.sec.auth.builtin.PKI-DH.private_key=file://$work/pki/$id/key.pem"
  expect "$p" "property dds.sec.access.builtin.Access-Permissions.permissions_ca=file://$work/pki/permissions_ca.pem"
  expect "$p" "property dds.sec.access.builtin.Access-Permissions.governance=file://$work/pki/governance.p7s"
  expect "$p" "property dds.sec.access.builtin.Access-Permissions.permissions=file://$work/pki/$id/permissions.p7s"
done
if ((${#create[@]})); then
  for id in service operator admin monitor; do expect "dh3_${id}_secure" "participant created"; done
  # What each identity may do, as Fast DDS enforces it from these profiles.
  for e in "writer dh3/hand_status" "writer dh3/hand_event" "writer dh3/service_info" \
    "writer dh3/command_reply" "reader dh3/command_request" "reader dh3/admin_request"; do
    expect dh3_service_secure "$e created"
  done
  expect dh3_service_secure "writer dh3/command_request refused"
  expect dh3_service_secure "writer dh3/admin_request refused"
  for p in dh3_operator_secure dh3_admin_secure; do
    for e in "reader dh3/hand_status" "reader dh3/hand_event" "reader dh3/service_info" \
      "reader dh3/command_reply" "writer dh3/command_request"; do
      expect "$p" "$e created"
    done
    expect "$p" "writer dh3/hand_status refused"
    expect "$p" "reader dh3/admin_request refused"
  done
  # Administration is the admin's alone: only its profile publishes admin requests.
  expect dh3_admin_secure "writer dh3/admin_request created"
  expect dh3_operator_secure "writer dh3/admin_request refused"
  expect dh3_monitor_secure "reader dh3/hand_status created"
  expect dh3_monitor_secure "reader dh3/hand_event created"
  for e in "writer dh3/command_request" "reader dh3/service_info" "reader dh3/command_reply" \
    "writer dh3/hand_status" "writer dh3/admin_request"; do
    expect dh3_monitor_secure "$e refused"
  done
fi

echo "== a profile that is not there is reported"
run_check "$dds/udp_only.xml" dh3_no_such_profile && fail "check_profiles exited 0 for a missing profile"
grep -qx "profile dh3_no_such_profile missing" "$work/out" || fail "a missing profile was not reported"

if ((failures)); then
  echo "$failures failure(s)"
  exit 1
fi
echo "profiles: all checks passed"
