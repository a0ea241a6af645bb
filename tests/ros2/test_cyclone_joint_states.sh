#!/usr/bin/env bash
# dh3-service on a simulated hand and dh3-ros2, read by a Cyclone DDS
# participant subscribing as rmw_cyclonedds does (cyclone_joint_states.c).
#   test_cyclone_joint_states.sh DH3_SERVICE DH3_ROS2 CYCLONE_JOINT_STATES
set -euo pipefail
service_bin=$1 ros2_bin=$2 reader_bin=$3
work=$(mktemp -d /tmp/dh3-ros2-cyclone-XXXXXX)
# shellcheck source=../support/processes.sh
source "$(dirname "$0")/../support/processes.sh"

# A domain of its own (sets $domain).
# shellcheck source=../support/test_domain.sh
source "$(dirname "$0")/../support/test_domain.sh"

"$service_bin" --domain "$domain" --name rosvendor --bus sim:1 >"$work/service.log" 2>&1 9>&- &
pids+=($!)
"$ros2_bin" --domain "$domain" >"$work/ros2.log" 2>&1 9>&- &
pids+=($!)
# Cyclone on loopback, where dh3's participants are by default.
export CYCLONEDDS_URI='<CycloneDDS><Domain><General><Interfaces><NetworkInterface name="lo"/></Interfaces></General></Domain></CycloneDDS>'
status=0
"$reader_bin" "$domain" rosvendor_bus0_1_finger_joint 60 >"$work/reader.log" 2>&1 9>&- || status=$?
head -5 "$work/reader.log"
if ((status != 0)); then
  echo "FAIL: the Cyclone reader saw no JointState of rosvendor/bus0/1 (exit $status)"
  echo "--- dh3-ros2:"; cat "$work/ros2.log"
  echo "--- dh3-service:"; cat "$work/service.log"
  exit 1
fi
echo "ok: Cyclone DDS read sensor_msgs::msg::dds_::JointState_ on rt/joint_states"
