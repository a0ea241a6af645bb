#pragma once
// A gripper action for one hand (control_msgs/action/GripperCommand or
// ParallelGripperCommand, by its ActionEndpoints), served as ROS 2's
// rcl_action lays an action out on DDS: the services send_goal, cancel_goal
// and get_result (RosServiceServer) and the topics feedback and status under
// "<action>/_action/"; the typed ones are the endpoints'. A goal moves the fingers to an opening
// with at most a force, holding the hand's lease meanwhile like any client: it ends SUCCEEDED with
// reached_goal (arrived) or stalled (stopped on an object), CANCELED after a cancel (the hand is
// stopped), ABORTED when the hand or the service refuses (the reason is logged: the result has no
// text). A goal that is NaN or out of range, or for a hand that is offline, not initialized or
// unknown, is rejected and sends nothing to the hand. A new goal cancels the
// one running, of this action or another of the hand's (HandTurn). Requests arrive on Fast DDS
// threads; each goal runs on a thread of its own, joined by the destructor.

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "action_endpoints.hpp"
#include "dh3/client.hpp"
#include "hand_turn.hpp"
#include "joint_units.hpp"
#include "ros2_interfacesPubSubTypes.h"

namespace dh3::ros2 {

class GripperActionServer {
 public:
  /// Makes the action's typed endpoints, given the handlers they call.
  using MakeEndpoints = std::function<std::unique_ptr<ActionEndpoints>(ActionEndpoints::Handlers)>;

  /// `action` is the fully qualified ROS name ("/dh3_bus0_1/gripper_cmd");
  /// `turn` is shared by every action and service of the hand.
  GripperActionServer(RosParticipant& participant, Client& client, HandAddress hand,
                      const std::string& action, JointUnits units, std::shared_ptr<HandTurn> turn,
                      const MakeEndpoints& make_endpoints);
  ~GripperActionServer();
  GripperActionServer(const GripperActionServer&) = delete;
  GripperActionServer& operator=(const GripperActionServer&) = delete;

  /// Every endpoint exists.
  [[nodiscard]] bool ok() const;

 private:
  struct Goal {
    Uuid id{};
    builtin_interfaces::msg::dds_::Time_ stamp;
    std::int8_t status = 0;
    GripperState result;
    std::vector<RequestId> waiting_for_result;
    HandTurn::Cancel cancel = std::make_shared<std::atomic<bool>>(false);
  };
  struct Target {
    std::int32_t position = 0;
    std::optional<std::int32_t> force;
  };

  void on_send_goal(const Uuid& goal_id, const Result<GripperGoal, std::string>& command,
                    const RequestId& id);
  void on_cancel_goal(const action_msgs::srv::dds_::CancelGoal_Request_& request,
                      const RequestId& id);
  void on_get_result(const Uuid& goal_id, const RequestId& id);
  /// The hand's percent for the goal, or why the goal is rejected.
  Result<Target, std::string> target_of(const GripperGoal& command);
  void execute(const std::shared_ptr<Goal>& goal, Target target);
  /// Moves and waits, publishing feedback; the status the goal ends with.
  std::int8_t move(Hand& hand, const std::shared_ptr<Goal>& goal, Target target);
  GripperState state_of(const std::optional<HandStatus>& status) const;
  void finish(const std::shared_ptr<Goal>& goal, std::int8_t status, GripperState result);
  void set_status(Goal& goal, std::int8_t status);
  void publish_status_locked();
  void forget_old_goals_locked();

  Client& client_;
  HandAddress hand_;
  std::string action_;
  JointUnits units_;
  std::shared_ptr<HandTurn> turn_;  // held by the goal that drives the hand
  std::mutex mutex_;                // goals_, workers_; taken after turn_
  std::map<Uuid, std::shared_ptr<Goal>> goals_;
  std::vector<std::thread> workers_;
  eprosima::fastdds::dds::DataWriter* status_ = nullptr;
  RosServiceServer<action_msgs::srv::dds_::CancelGoal_Request_,
                   action_msgs::srv::dds_::CancelGoal_Request_PubSubType,
                   action_msgs::srv::dds_::CancelGoal_Response_,
                   action_msgs::srv::dds_::CancelGoal_Response_PubSubType>
      cancel_goal_;
  std::mutex endpoints_made_;                   // held while the constructor makes endpoints_
  std::unique_ptr<ActionEndpoints> endpoints_;  // last: its handlers use the rest
};

}  // namespace dh3::ros2
