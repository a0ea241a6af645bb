#!/usr/bin/env bash
# The ROS 2 names as announced on the wire: tshark captures loopback while
# dh3-service (a simulated hand), dh3-ros2 and a Cyclone DDS peer (which makes
# dh3-ros2's participant announce its endpoints) run on a domain of their own,
# then lists every topic and type name of the discovery data. Needs tshark and
# the right to capture (root); skips and says why otherwise.
#   test_tshark_names.sh DH3_SERVICE DH3_ROS2 CYCLONE_JOINT_STATES
set -euo pipefail
service_bin=$1 ros2_bin=$2 peer_bin=$3
command -v tshark >/dev/null || { echo "SKIP: tshark is not installed"; exit 77; }
((EUID == 0)) || { echo "SKIP: capturing on loopback needs root"; exit 77; }
work=$(mktemp -d /tmp/dh3-ros2-tshark-XXXXXX)
pids=()
tshark_pid=
cleanup() {
  for pid in "${pids[@]}" $tshark_pid; do kill "$pid" 2>/dev/null || true; wait "$pid" 2>/dev/null || true; done
  rm -rf "$work"
}
trap cleanup EXIT

# A domain of its own (sets $domain).
# shellcheck source=../support/test_domain.sh
source "$(dirname "$0")/../support/test_domain.sh"
# RTPS's ports of the domain: 7400 + 250 * domain and the 250 after.
base=$((7400 + 250 * domain))
tshark -i lo -f "udp portrange $base-$((base + 249))" -w "$work/capture.pcap" \
  >"$work/tshark.log" 2>&1 9>&- &
tshark_pid=$!
for ((i = 0; i < 600; i++)); do
  grep -q "Capturing on" "$work/tshark.log" && break
  kill -0 "$tshark_pid" 2>/dev/null || { cat "$work/tshark.log"; echo "SKIP: tshark cannot capture on lo"; exit 77; }
  sleep 0.1
done

"$service_bin" --domain "$domain" --name wire --bus sim:1 >"$work/service.log" 2>&1 9>&- &
pids+=($!)
"$ros2_bin" --domain "$domain" >"$work/ros2.log" 2>&1 9>&- &
pids+=($!)
export CYCLONEDDS_URI='<CycloneDDS><Domain><General><Interfaces><NetworkInterface name="lo"/></Interfaces></General></Domain></CycloneDDS>'
"$peer_bin" "$domain" wire_bus0_1_finger_joint 60 >/dev/null 2>&1 9>&- ||
  { echo "FAIL: the peer saw no joint state"; cat "$work/ros2.log"; exit 1; }
hand=wire_bus0_1
# An action's three services and two topics: action_names NAME TYPE.
action_names() {
  local action=$hand/$1/_action type=control_msgs::action::dds_::$2
  echo "rq/$action/cancel_goalRequest action_msgs::srv::dds_::CancelGoal_Request_
rq/$action/get_resultRequest ${type}_GetResult_Request_
rq/$action/send_goalRequest ${type}_SendGoal_Request_
rr/$action/cancel_goalReply action_msgs::srv::dds_::CancelGoal_Response_
rr/$action/get_resultReply ${type}_GetResult_Response_
rr/$action/send_goalReply ${type}_SendGoal_Response_
rt/$action/feedback ${type}_FeedbackMessage_
rt/$action/status action_msgs::msg::dds_::GoalStatusArray_"
}
expected="$(action_names gripper_cmd GripperCommand)
$(action_names parallel_gripper_cmd ParallelGripperCommand)
rq/$hand/initializeRequest std_srvs::srv::dds_::Trigger_Request_
rr/$hand/initializeReply std_srvs::srv::dds_::Trigger_Response_
rq/$hand/set_forcesRequest rcl_interfaces::srv::dds_::SetParameters_Request_
rr/$hand/set_forcesReply rcl_interfaces::srv::dds_::SetParameters_Response_
rt/joint_states sensor_msgs::msg::dds_::JointState_
ros_discovery_info rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_"
# "topic type" lines from tshark's fields, where a packet that announces several
# endpoints lists their topics, then their types, each joined by commas.
pairs() {
  awk -F'\t' '{ n = split($1, topics, ","); split($2, types, ",");
                for (i = 1; i <= n; i++) print topics[i], types[i] }'
}
# The names announced so far, read from the capture as it grows, until every
# expected one is there or 30 s passed.
for ((i = 0; i < 60; i++)); do
  tshark -r "$work/capture.pcap" -Y rtps -T fields -e rtps.param.topicName -e rtps.param.typeName \
    2>/dev/null | pairs | grep -E '^(r[tqr]/|ros_discovery_info )' | sort -u >"$work/names.txt" || true
  missing=$(comm -23 <(sort <<<"$expected") "$work/names.txt")
  [[ -z $missing ]] && break
  sleep 0.5
done
kill -INT "$tshark_pid"
wait "$tshark_pid" 2>/dev/null || true
tshark_pid=
cat "$work/names.txt"
if [[ -n $missing ]]; then
  echo "FAIL: not announced on the wire:"
  echo "$missing"
  exit 1
fi
echo "ok: every ROS 2 topic and type name as expected on the wire"
