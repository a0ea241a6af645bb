#!/usr/bin/env bash
# deploy/container/healthcheck.sh (the image's dh3-healthcheck, used by the
# Dockerfile's HEALTHCHECK and the Kubernetes probes) against a real
# dh3-service running the image's default configuration: healthy while it
# serves, unhealthy for another name and once it stopped.
#
#   test_healthcheck.sh SOURCE_DIR DH3_SERVICE DH3CTL
set -uo pipefail
src=$1 service_bin=$2 ctl_bin=$3
check=$src/deploy/container/healthcheck.sh
work=$(mktemp -d)
service_pid=
cleanup() {
  [[ -n $service_pid ]] && kill "$service_pid" 2>/dev/null && wait "$service_pid" 2>/dev/null
  rm -rf "$work"
}
trap cleanup EXIT
failures=0
fail() { echo "FAILED: $*"; failures=$((failures + 1)); }
ok() { echo "ok: $*"; }

# A domain of its own (sets $domain): other tests run beside it.
# shellcheck source=../support/test_domain.sh
source "$(dirname "$0")/../support/test_domain.sh"
# The image's configuration, kept on loopback (it says every interface), its
# metrics on a free port (its fixed one may be taken by a parallel test).
"$service_bin" --config "$src/deploy/config/dh3-sim.yaml" --domain "$domain" \
  --interface 127.0.0.1 --metrics 127.0.0.1:0 >"$work/service.log" 2>&1 &
service_pid=$!

export PATH="$(dirname "$ctl_bin"):$PATH" DH3_DOMAIN=$domain DH3_HEALTH_INTERFACE=127.0.0.1
name=$(sed -n 's/^name: *//p' "$src/deploy/config/dh3-sim.yaml")
# The check's own timeout is generous; the first run also waits for start-up.
if DH3_SERVICE=$name DH3_HEALTH_TIMEOUT=20 "$check"; then
  ok "healthy while dh3-service '$name' serves"
else
  fail "unhealthy although dh3-service '$name' serves"
  sed 's/^/  /' "$work/service.log"
fi
if DH3_SERVICE=not-$name DH3_HEALTH_TIMEOUT=5 "$check" >"$work/out"; then
  fail "healthy for a service that does not exist"
else
  ok "unhealthy for another service name: $(cat "$work/out")"
fi
kill -TERM "$service_pid"
wait "$service_pid"
status=$?
service_pid=
((status == 0)) && ok "dh3-service stopped cleanly" || fail "dh3-service exit status $status on SIGTERM"
if DH3_SERVICE=$name DH3_HEALTH_TIMEOUT=5 "$check" >"$work/out"; then
  fail "healthy after the service stopped"
else
  ok "unhealthy once the service stopped"
fi

if ((failures)); then
  echo "$failures failure(s)"
  exit 1
fi
echo "healthcheck: all checks passed"
