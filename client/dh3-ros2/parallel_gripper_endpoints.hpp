#pragma once
// control_msgs/action/ParallelGripperCommand's typed endpoints under
// "<action>/_action/": send_goal, get_result and feedback. A goal is a
// sensor_msgs/JointState for the hand's finger joint, as
// parallel_gripper_action_controller takes it: exactly one position (the
// opening), an optional effort (the largest closing force), names empty or
// the finger joint's; a velocity is ignored (the hand takes no speed). The
// state in results and feedback is the finger joint's position and effort.

#include "action_endpoints.hpp"
#include "ros2_interfacesPubSubTypes.h"

namespace dh3::ros2 {

namespace pgc = control_msgs::action::dds_;

class ParallelGripperEndpoints : public ActionEndpoints {
 public:
  /// `action` is the fully qualified ROS name; `finger_joint` the hand's
  /// finger joint name, as in its joint states.
  ParallelGripperEndpoints(RosParticipant& participant, const std::string& action,
                           std::string finger_joint, Handlers handlers);

  [[nodiscard]] bool ok() const override;
  void reply_goal(const RequestId& id, bool accepted,
                  const builtin_interfaces::msg::dds_::Time_& stamp) override;
  void reply_result(const RequestId& id, std::int8_t status, const GripperState& state) override;
  void publish_feedback(const Uuid& goal, const GripperState& state) override;

  /// The goal a command names, or why it is none for `finger_joint`.
  [[nodiscard]] static Result<GripperGoal, std::string> goal_of(
      const sensor_msgs::msg::dds_::JointState_& command, const std::string& finger_joint);

 private:
  [[nodiscard]] sensor_msgs::msg::dds_::JointState_ joint_state_of(const GripperState& state) const;

  std::string finger_joint_;
  Handlers handlers_;
  eprosima::fastdds::dds::DataWriter* feedback_ = nullptr;
  RosServiceServer<pgc::ParallelGripperCommand_SendGoal_Request_,
                   pgc::ParallelGripperCommand_SendGoal_Request_PubSubType,
                   pgc::ParallelGripperCommand_SendGoal_Response_,
                   pgc::ParallelGripperCommand_SendGoal_Response_PubSubType>
      send_goal_;
  RosServiceServer<pgc::ParallelGripperCommand_GetResult_Request_,
                   pgc::ParallelGripperCommand_GetResult_Request_PubSubType,
                   pgc::ParallelGripperCommand_GetResult_Response_,
                   pgc::ParallelGripperCommand_GetResult_Response_PubSubType>
      get_result_;
};

}  // namespace dh3::ros2
