#!/bin/sh
# dh3-healthcheck: exit 0 when the dh3-service named DH3_SERVICE (default cell)
# answers on DDS domain DH3_DOMAIN (default 0): dh3ctl sees it and it says it is
# ready. For the container image's HEALTHCHECK and Kubernetes probes; it runs
# in the service's own container, with the service's environment (including
# ROS_DISCOVERY_SERVER, which Fast DDS applies to dh3ctl as well).
#
#   DH3_SERVICE          the service's name (config key name)
#   DH3_DOMAIN           its DDS domain (config key domain)
#   DH3_HEALTH_TIMEOUT   seconds dh3ctl waits for it (default 5)
#   DH3_HEALTH_INTERFACE the interface dh3ctl uses (default *: all); where the
#                        service listens on loopback only, 127.0.0.1
set -u
service=${DH3_SERVICE:-cell}
out=$(dh3ctl --json --udp-only --timeout "${DH3_HEALTH_TIMEOUT:-5}" --domain "${DH3_DOMAIN:-0}" \
  --interface "${DH3_HEALTH_INTERFACE:-*}" list 2>&1) || { echo "dh3-healthcheck: $out"; exit 1; }
# One JSON object per line; the service's line names it and says ready.
if printf '%s\n' "$out" | grep '"type":"service"' | grep "\"service\":\"$service\"" |
  grep -q '"ready":true'; then
  exit 0
fi
echo "dh3-healthcheck: service '$service' is not ready on domain ${DH3_DOMAIN:-0}"
exit 1
