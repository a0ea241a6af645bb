#!/usr/bin/env bash
# dh3-service on a simulated hand, and a participant of Eclipse Cyclone DDS
# built from idl/dh3.idl (cyclone_client.c): it must see the hand's status,
# match the service's request reader and get an OK reply to a command. Then,
# as docs/contract.md says, a Cyclone participant that took a hand's lease under its
# GUID prefix is seen to leave the domain at once when it sends key hashes
# (Cyclone's Internal/GenerateKeyhash), and otherwise drops out when its DDS
# lease runs out: the service's log says which of the two ended the lease.
# Last, a Cyclone participant that learnt the holder's client_id and writes it
# into its own MOVE is DENIED and the hand does not move, and the published
# holder is the holder's name, not that id.
#
#   test_cyclone_client.sh DH3_SERVICE CYCLONE_CLIENT
set -euo pipefail
service_bin=$1 client_bin=$2
work=$(mktemp -d /tmp/dh3-vendor-XXXXXX)
service_pid=
cleanup() {
  if [[ -n $service_pid ]]; then
    kill "$service_pid" 2>/dev/null || true
    wait "$service_pid" 2>/dev/null || true
  fi
  rm -rf "$work"
}
trap cleanup EXIT

# A domain of its own (sets $domain).
# shellcheck source=../../support/test_domain.sh
source "$(dirname "$0")/../../support/test_domain.sh"

"$service_bin" --domain "$domain" --name vendor --bus sim:1 >"$work/service.log" 2>&1 9>&- &
service_pid=$!
for ((i = 0; i < 200; i++)); do
  grep -q "service 'vendor' on DDS domain" "$work/service.log" && break
  kill -0 "$service_pid" 2>/dev/null || { cat "$work/service.log"; echo "dh3-service ended"; exit 1; }
  sleep 0.1
done

# Cyclone on loopback, where dh3-service is by default (it discovers by unicast there).
export CYCLONEDDS_URI='<CycloneDDS><Domain><General><Interfaces><NetworkInterface name="lo"/></Interfaces></General></Domain></CycloneDDS>'
status=0
"$client_bin" "$domain" vendor 1 60 >"$work/client.log" 2>&1 9>&- || status=$?
cat "$work/client.log"
case $status in
  0) ;;
  2) echo "FAIL: the Cyclone participant never read the hand's status" ;;
  3) echo "FAIL: the Cyclone participant's request writer never matched the service" ;;
  4) echo "FAIL: no reply to the Cyclone participant's request" ;;
  5) echo "FAIL: the reply was not OK" ;;
  *) echo "FAIL: cyclone_client exited with $status" ;;
esac
if ((status != 0)); then
  echo "--- dh3-service's log:"
  cat "$work/service.log"
  exit 1
fi
grep -q "^reply code 0 " "$work/client.log" || { echo "FAIL: no OK reply printed"; exit 1; }
echo "PASS: Eclipse Cyclone DDS read the status, and its command was answered OK"

# lease_ends_as KEYHASH EXPECTED: takes the lease, leaves, and waits for the
# service to end the lease the EXPECTED way ("left" or "dropped out of").
# The Cyclone participant's DDS lease is 3 s, the dh3 lease 600 s: only the
# participant's departure can end it within the deadline.
lease_ends_as() {
  local keyhash=$1 expected=$2 id
  CYCLONEDDS_URI="<CycloneDDS><Domain><General><Interfaces><NetworkInterface name=\"lo\"/></Interfaces></General><Discovery><LeaseDuration>3s</LeaseDuration></Discovery><Internal><GenerateKeyhash>$keyhash</GenerateKeyhash></Internal></Domain></CycloneDDS>" \
    "$client_bin" "$domain" vendor 1 60 lease >"$work/lease.log" 2>&1 9>&- ||
    { cat "$work/lease.log"; echo "FAIL: the Cyclone participant could not take the lease"; return 1; }
  id=$(sed -n 's/^client_id //p' "$work/lease.log")
  for ((i = 0; i < 300; i++)); do
    if grep -q "(participant $id) ended, its participant $expected the domain" "$work/service.log"; then
      echo "PASS: GenerateKeyhash $keyhash: the lease ended as its participant $expected the domain"
      return 0
    fi
    sleep 0.1
  done
  echo "FAIL: GenerateKeyhash $keyhash: no \"participant $expected the domain\" for lease holder '$id'"
  cat "$work/service.log"
  return 1
}
lease_ends_as true left
lease_ends_as false "dropped out of"

# The holder stays (hold) while another Cyclone participant forges its client_id.
"$client_bin" "$domain" vendor 1 120 hold >"$work/hold.log" 2>&1 9>&- &
holder_pid=$!
for ((i = 0; i < 600; i++)); do
  grep -q "^holding" "$work/hold.log" && break
  kill -0 "$holder_pid" 2>/dev/null || break
  sleep 0.1
done
if ! grep -q "^holding" "$work/hold.log"; then
  kill "$holder_pid" 2>/dev/null || true
  cat "$work/hold.log"
  echo "FAIL: the holding Cyclone participant could not take the lease and move the hand"
  exit 1
fi
holder_id=$(sed -n 's/^client_id //p' "$work/hold.log")
forge_status=0
"$client_bin" "$domain" vendor 1 60 forge "$holder_id" >"$work/forge.log" 2>&1 9>&- || forge_status=$?
kill "$holder_pid" 2>/dev/null || true
wait "$holder_pid" 2>/dev/null || true
cat "$work/forge.log"
case $forge_status in
  0) ;;
  5) echo "FAIL: the forged MOVE was not answered DENIED"; exit 1 ;;
  6) echo "FAIL: the hand took the forged MOVE's target"; exit 1 ;;
  *) echo "FAIL: the forging participant ended with $forge_status"; cat "$work/service.log"; exit 1 ;;
esac
grep -q "a lease belongs to the participant that took it" "$work/forge.log" ||
  { echo "FAIL: the DENIED reply does not say why"; exit 1; }
holder_shown=$(sed -n "s/^lease_holder '\(.*\)' target_position.*/\1/p" "$work/forge.log" | tail -1)
if [[ -z $holder_shown || $holder_shown == *"$holder_id"* ]]; then
  echo "FAIL: the published lease holder is '$holder_shown', not a name without the holder's id"
  exit 1
fi
echo "PASS: a forged client_id of the holder is DENIED, the hand's target stays, the holder is shown as '$holder_shown'"
