// Prints dh3-ros2's messages as they go on the wire, one line each:
// "DDS_TYPE_NAME HEX" (the encapsulation header and the XCDR1 body), and
// " DISTRO" after it for a layout of one ROS 2 distribution only. The
// JointState is made from a fixed hand status by dh3-ros2's own conversion
// with the default units, ros_discovery_info by its own from fixed GUIDs;
// every other message from fixed values.
// check_golden.js encodes the same messages with an independent encoder
// (npm @foxglove/rosmsg2-serialization) and compares.

#include <fastdds/rtps/common/SerializedPayload.h>

#include <cstdio>
#include <numeric>

#include "discovery_info.hpp"
#include "joint_state_message.hpp"
#include "ros2_interfacesPubSubTypes.h"

namespace {

namespace am = action_msgs::msg::dds_;
namespace as = action_msgs::srv::dds_;
namespace ca = control_msgs::action::dds_;

constexpr std::int32_t kSec = 1'700'000'000;
constexpr std::uint32_t kNanosec = 123'456'789;

void print_with(eprosima::fastdds::dds::TopicDataType& type, void* message, const char* distro) {
  eprosima::fastrtps::rtps::SerializedPayload_t payload(type.getSerializedSizeProvider(message)());
  if (!type.serialize(message, &payload)) {
    std::printf("%s SERIALIZE_FAILED\n", type.getName());
    return;
  }
  std::printf("%s ", type.getName());
  for (std::uint32_t i = 0; i < payload.length; ++i) std::printf("%02x", payload.data[i]);
  std::printf(distro != nullptr ? " %s\n" : "\n", distro);
}

template <typename PubSub, typename Message>
void print(Message message, const char* distro = nullptr) {
  PubSub type;
  print_with(type, &message, distro);
}

unique_identifier_msgs::msg::dds_::UUID_ uuid() {
  unique_identifier_msgs::msg::dds_::UUID_ id;
  std::iota(id.uuid().begin(), id.uuid().end(), std::uint8_t{0});
  return id;
}

builtin_interfaces::msg::dds_::Time_ stamp() {
  builtin_interfaces::msg::dds_::Time_ time;
  time.sec(kSec);
  time.nanosec(kNanosec);
  return time;
}

am::GoalInfo_ goal_info() {
  am::GoalInfo_ info;
  info.goal_id(uuid());
  info.stamp(stamp());
  return info;
}

void print_joint_state() {
  dh3::HandStatus status;
  status.address = {"dh3", "bus0", 1};
  status.online = status.initialized = true;
  status.grip = dh3::GripState::grasped;
  status.position = 40;
  status.rotation = 50;
  status.closing_force = 60;
  status.read_at_ns = static_cast<std::uint64_t>(kSec) * 1'000'000'000 + kNanosec;
  print<sensor_msgs::msg::dds_::JointState_PubSubType>(
      dh3::ros2::joint_state_of(status, dh3::ros2::JointNames{}, dh3::ros2::JointUnits{}));
}

void print_action_msgs() {
  am::GoalStatus_ status;
  status.goal_info(goal_info());
  status.status(2);
  am::GoalStatusArray_ array;
  array.status_list({status, status});
  print<am::GoalStatusArray_PubSubType>(array);
  as::CancelGoal_Request_ cancel;
  cancel.goal_info(goal_info());
  print<as::CancelGoal_Request_PubSubType>(cancel);
  as::CancelGoal_Response_ canceling;
  canceling.return_code(0);
  canceling.goals_canceling({goal_info()});
  print<as::CancelGoal_Response_PubSubType>(canceling);
}

void print_gripper_command() {
  ca::GripperCommand_SendGoal_Request_ goal;
  goal.goal_id(uuid());
  goal.goal().command().position(0.02);
  goal.goal().command().max_effort(20.0);
  print<ca::GripperCommand_SendGoal_Request_PubSubType>(goal);
  ca::GripperCommand_SendGoal_Response_ accepted;
  accepted.accepted(true);
  accepted.stamp(stamp());
  print<ca::GripperCommand_SendGoal_Response_PubSubType>(accepted);
  ca::GripperCommand_GetResult_Request_ ask;
  ask.goal_id(uuid());
  print<ca::GripperCommand_GetResult_Request_PubSubType>(ask);
  ca::GripperCommand_GetResult_Response_ result;
  result.status(4);
  result.result().position(0.0285);
  result.result().effort(54.0);
  result.result().stalled(true);
  result.result().reached_goal(false);
  print<ca::GripperCommand_GetResult_Response_PubSubType>(result);
  ca::GripperCommand_FeedbackMessage_ feedback;
  feedback.goal_id(uuid());
  feedback.feedback().position(0.05);
  feedback.feedback().effort(0.0);
  feedback.feedback().stalled(false);
  feedback.feedback().reached_goal(false);
  print<ca::GripperCommand_FeedbackMessage_PubSubType>(feedback);
}

sensor_msgs::msg::dds_::JointState_ finger_joint(double position, double effort) {
  sensor_msgs::msg::dds_::JointState_ joint;
  joint.header().stamp(stamp());
  joint.name({"dh3_bus0_1_finger_joint"});
  joint.position({position});
  joint.effort({effort});
  return joint;
}

void print_parallel_gripper_command() {
  ca::ParallelGripperCommand_SendGoal_Request_ goal;
  goal.goal_id(uuid());
  goal.goal().command(finger_joint(0.02, 20.0));
  print<ca::ParallelGripperCommand_SendGoal_Request_PubSubType>(goal);
  ca::ParallelGripperCommand_SendGoal_Response_ accepted;
  accepted.accepted(true);
  accepted.stamp(stamp());
  print<ca::ParallelGripperCommand_SendGoal_Response_PubSubType>(accepted);
  ca::ParallelGripperCommand_GetResult_Request_ ask;
  ask.goal_id(uuid());
  print<ca::ParallelGripperCommand_GetResult_Request_PubSubType>(ask);
  ca::ParallelGripperCommand_GetResult_Response_ result;
  result.status(4);
  result.result().state(finger_joint(0.0285, 54.0));
  result.result().stalled(true);
  result.result().reached_goal(false);
  print<ca::ParallelGripperCommand_GetResult_Response_PubSubType>(result);
  ca::ParallelGripperCommand_FeedbackMessage_ feedback;
  feedback.goal_id(uuid());
  feedback.feedback().state(finger_joint(0.05, 0.0));
  print<ca::ParallelGripperCommand_FeedbackMessage_PubSubType>(feedback);
}

void print_services() {
  std_srvs::srv::dds_::Trigger_Request_ trigger;
  print<std_srvs::srv::dds_::Trigger_Request_PubSubType>(trigger);
  std_srvs::srv::dds_::Trigger_Response_ triggered;
  triggered.success(true);
  triggered.message("initialized");
  print<std_srvs::srv::dds_::Trigger_Response_PubSubType>(triggered);
  namespace rm = rcl_interfaces::msg::dds_;
  namespace rs = rcl_interfaces::srv::dds_;
  rm::Parameter_ closing;
  closing.name("closing_force");
  closing.value().type(3);
  closing.value().double_value(40.5);
  rm::Parameter_ opening;
  opening.name("opening_force");
  opening.value().type(2);
  opening.value().integer_value(30);
  rs::SetParameters_Request_ set;
  set.parameters({closing, opening});
  print<rs::SetParameters_Request_PubSubType>(set);
  rm::SetParametersResult_ done;
  done.successful(true);
  rm::SetParametersResult_ refused;
  refused.successful(false);
  refused.reason("opening_force 300 is out of range");
  rs::SetParameters_Response_ results;
  results.results({done, refused});
  print<rs::SetParameters_Response_PubSubType>(results);
}

eprosima::fastrtps::rtps::GUID_t guid(std::uint8_t first, std::uint8_t kind) {
  eprosima::fastrtps::rtps::GUID_t guid;
  std::iota(std::begin(guid.guidPrefix.value), std::end(guid.guidPrefix.value), first);
  guid.entityId.value[0] = 0;
  guid.entityId.value[1] = first;
  guid.entityId.value[2] = 0x01;
  guid.entityId.value[3] = kind;
  return guid;
}

void print_discovery_info() {
  dh3::ros2::DiscoveryEntities entities;
  entities.participant = guid(1, 0xc1);
  entities.node_namespace = "/cell";
  entities.node_name = "dh3_ros2";
  entities.readers = {guid(2, 0x04)};
  entities.writers = {guid(3, 0x03), guid(4, 0x03)};
  print<rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_PubSubType>(
      dh3::ros2::jazzy_discovery_info(entities), "ros2jazzy");
  // The Humble layout, as announced: under rmw_dds_common's type name.
  auto humble = dh3::ros2::discovery_info_type(dh3::ros2::RosDistro::humble);
  auto message = dh3::ros2::humble_discovery_info(entities);
  print_with(*humble, &message, "ros2humble");
}

}  // namespace

int main() {
  print_joint_state();
  print_action_msgs();
  print_gripper_command();
  print_parallel_gripper_command();
  print_services();
  print_discovery_info();
  return 0;
}
