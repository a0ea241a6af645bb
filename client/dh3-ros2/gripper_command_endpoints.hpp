#pragma once
// control_msgs/action/GripperCommand's typed endpoints under
// "<action>/_action/": send_goal, get_result and feedback. A goal is
// command.position (the opening) and command.max_effort.

#include "action_endpoints.hpp"
#include "ros2_interfacesPubSubTypes.h"

namespace dh3::ros2 {

namespace gc = control_msgs::action::dds_;

class GripperCommandEndpoints : public ActionEndpoints {
 public:
  /// `action` is the fully qualified ROS name ("/dh3_bus0_1/gripper_cmd").
  GripperCommandEndpoints(RosParticipant& participant, const std::string& action,
                          Handlers handlers);

  [[nodiscard]] bool ok() const override;
  void reply_goal(const RequestId& id, bool accepted,
                  const builtin_interfaces::msg::dds_::Time_& stamp) override;
  void reply_result(const RequestId& id, std::int8_t status, const GripperState& state) override;
  void publish_feedback(const Uuid& goal, const GripperState& state) override;

 private:
  Handlers handlers_;
  eprosima::fastdds::dds::DataWriter* feedback_ = nullptr;
  RosServiceServer<
      gc::GripperCommand_SendGoal_Request_, gc::GripperCommand_SendGoal_Request_PubSubType,
      gc::GripperCommand_SendGoal_Response_, gc::GripperCommand_SendGoal_Response_PubSubType>
      send_goal_;
  RosServiceServer<
      gc::GripperCommand_GetResult_Request_, gc::GripperCommand_GetResult_Request_PubSubType,
      gc::GripperCommand_GetResult_Response_, gc::GripperCommand_GetResult_Response_PubSubType>
      get_result_;
};

}  // namespace dh3::ros2
