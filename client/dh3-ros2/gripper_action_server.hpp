#pragma once
// control_msgs/action/GripperCommand for one hand, served as ROS 2's
// rcl_action lays an action out on DDS: the services send_goal, cancel_goal
// and get_result (RosServiceServer) and the topics feedback and status under
// "<action>/_action/". A goal moves the fingers to an opening with at most a
// force, holding the hand's lease meanwhile like any client: it ends
// SUCCEEDED with reached_goal (arrived) or stalled (stopped on an object),
// CANCELED after a cancel (the hand is stopped), ABORTED when the hand or the
// service refuses (the reason is logged: the result has no text). A goal that
// is NaN or out of range, or for a hand that is offline, not initialized or
// unknown, is rejected and sends nothing to the hand. A new goal cancels the
// one running. Requests arrive on Fast DDS threads; each goal runs on a
// thread of its own, joined by the destructor.

#include <array>
#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "dh3/client.hpp"
#include "joint_units.hpp"
#include "ros2_interfacesPubSubTypes.h"
#include "ros_service_server.hpp"

namespace dh3::ros2 {

namespace gc = control_msgs::action::dds_;

class GripperActionServer {
 public:
  /// `action` is the fully qualified ROS name ("/dh3_bus0_1/gripper_cmd").
  GripperActionServer(RosParticipant& participant, Client& client, HandAddress hand,
                      const std::string& action, JointUnits units);
  ~GripperActionServer();
  GripperActionServer(const GripperActionServer&) = delete;
  GripperActionServer& operator=(const GripperActionServer&) = delete;

  /// Every endpoint exists.
  [[nodiscard]] bool ok() const;

 private:
  using Uuid = std::array<std::uint8_t, 16>;
  struct Goal {
    Uuid id{};
    builtin_interfaces::msg::dds_::Time_ stamp;
    std::int8_t status = 0;
    gc::GripperCommand_Result_ result;
    std::vector<RequestId> waiting_for_result;
    std::atomic<bool> cancel{false};
  };
  struct Target {
    std::int32_t position = 0;
    std::optional<std::int32_t> force;
  };

  void on_send_goal(const gc::GripperCommand_SendGoal_Request_& request, const RequestId& id);
  void on_cancel_goal(const action_msgs::srv::dds_::CancelGoal_Request_& request,
                      const RequestId& id);
  void on_get_result(const gc::GripperCommand_GetResult_Request_& request, const RequestId& id);
  /// The hand's percent for the goal, or why the goal is rejected.
  Result<Target, std::string> target_of(const control_msgs::msg::dds_::GripperCommand_& command);
  void execute(const std::shared_ptr<Goal>& goal, Target target);
  /// Moves and waits, publishing feedback; the status the goal ends with.
  std::int8_t move(Hand& hand, const std::shared_ptr<Goal>& goal, Target target);
  void publish_feedback(const Goal& goal, const gc::GripperCommand_Result_& state);
  gc::GripperCommand_Result_ state_of(const std::optional<HandStatus>& status) const;
  void finish(const std::shared_ptr<Goal>& goal, std::int8_t status,
              gc::GripperCommand_Result_ result);
  void set_status(Goal& goal, std::int8_t status);
  void publish_status_locked();
  void forget_old_goals_locked();

  Client& client_;
  HandAddress hand_;
  std::string action_;
  JointUnits units_;
  std::mutex executing_;  // held by the goal that drives the hand
  std::mutex mutex_;      // goals_, running_, workers_; taken after executing_
  std::map<Uuid, std::shared_ptr<Goal>> goals_;
  std::shared_ptr<Goal> running_;
  std::vector<std::thread> workers_;
  eprosima::fastdds::dds::DataWriter* feedback_ = nullptr;
  eprosima::fastdds::dds::DataWriter* status_ = nullptr;
  RosServiceServer<
      gc::GripperCommand_SendGoal_Request_, gc::GripperCommand_SendGoal_Request_PubSubType,
      gc::GripperCommand_SendGoal_Response_, gc::GripperCommand_SendGoal_Response_PubSubType>
      send_goal_;
  RosServiceServer<action_msgs::srv::dds_::CancelGoal_Request_,
                   action_msgs::srv::dds_::CancelGoal_Request_PubSubType,
                   action_msgs::srv::dds_::CancelGoal_Response_,
                   action_msgs::srv::dds_::CancelGoal_Response_PubSubType>
      cancel_goal_;
  RosServiceServer<
      gc::GripperCommand_GetResult_Request_, gc::GripperCommand_GetResult_Request_PubSubType,
      gc::GripperCommand_GetResult_Response_, gc::GripperCommand_GetResult_Response_PubSubType>
      get_result_;
};

}  // namespace dh3::ros2
