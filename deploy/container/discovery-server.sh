#!/bin/sh
# dh3-discovery-server: fast-discovery-server (Fast DDS's discovery server, the
# program `fastdds discovery` runs) with its arguments, stopped cleanly by
# SIGTERM as well. The server handles SIGINT only (shuts down, exit 0). As a
# container's PID 1 it never sees the SIGTERM that `docker stop`, `podman
# stop`, Compose's `down` and Kubernetes send (the kernel drops signals PID 1
# has no handler for), so it was killed after the grace period (exit 137);
# elsewhere SIGTERM kills it (143). This script, PID 1 in its place, passes
# SIGTERM and SIGINT on as SIGINT and exits with the server's status.
#
#   dh3-discovery-server -i 0 -l 0.0.0.0 -p 11811
set -u
# (A non-interactive shell starts it with SIGINT ignored; the server installs
# its own handler, so SIGINT reaches it all the same.)
fast-discovery-server "$@" &
server=$!
signalled=
trap 'signalled=yes; kill -INT "$server" 2>/dev/null' TERM INT
while :; do
  wait "$server"
  status=$?
  # A trapped signal ends `wait` early (status above 128); wait on.
  if [ "$status" -gt 128 ] && [ -n "$signalled" ] && kill -0 "$server" 2>/dev/null; then
    signalled=
    continue
  fi
  exit "$status"
done
