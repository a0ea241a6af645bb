#pragma once
// dh3-ros2 beside dh3-service on the simulator (hand 1 has an object at 40 %;
// fingers move 50 %/s so a goal can be cancelled while it moves), and the
// hands' actions and services as an rmw_fastrtps-style client uses them
// (ros_action_client.hpp).

#include <gtest/gtest.h>

#include <map>
#include <memory>

#include "integration/client/client_fixture.hpp"
#include "ros2_interfacesPubSubTypes.h"
#include "ros_action_client.hpp"

namespace dh3::test {

namespace ca = control_msgs::action::dds_;
namespace as = action_msgs::srv::dds_;
using Uuid = std::array<std::uint8_t, 16>;

constexpr std::int8_t kSucceeded = 4;
constexpr std::int8_t kCanceled = 5;

/// control_msgs/action/GripperCommand's types, for ActionClient.
struct GripperCommandTypes {
  using SendGoalRequest = ca::GripperCommand_SendGoal_Request_;
  using SendGoalRequestType = ca::GripperCommand_SendGoal_Request_PubSubType;
  using SendGoalResponse = ca::GripperCommand_SendGoal_Response_;
  using SendGoalResponseType = ca::GripperCommand_SendGoal_Response_PubSubType;
  using GetResultRequest = ca::GripperCommand_GetResult_Request_;
  using GetResultRequestType = ca::GripperCommand_GetResult_Request_PubSubType;
  using GetResultResponse = ca::GripperCommand_GetResult_Response_;
  using GetResultResponseType = ca::GripperCommand_GetResult_Response_PubSubType;
  using FeedbackMessage = ca::GripperCommand_FeedbackMessage_;
  using FeedbackMessageType = ca::GripperCommand_FeedbackMessage_PubSubType;
  static void set_goal(SendGoalRequest& request, double position, double max_effort) {
    request.goal().command().position(position);
    request.goal().command().max_effort(max_effort);
  }
};

/// control_msgs/action/ParallelGripperCommand's: a goal names the finger
/// joint, its position and, when positive, its effort.
struct ParallelGripperTypes {
  using SendGoalRequest = ca::ParallelGripperCommand_SendGoal_Request_;
  using SendGoalRequestType = ca::ParallelGripperCommand_SendGoal_Request_PubSubType;
  using SendGoalResponse = ca::ParallelGripperCommand_SendGoal_Response_;
  using SendGoalResponseType = ca::ParallelGripperCommand_SendGoal_Response_PubSubType;
  using GetResultRequest = ca::ParallelGripperCommand_GetResult_Request_;
  using GetResultRequestType = ca::ParallelGripperCommand_GetResult_Request_PubSubType;
  using GetResultResponse = ca::ParallelGripperCommand_GetResult_Response_;
  using GetResultResponseType = ca::ParallelGripperCommand_GetResult_Response_PubSubType;
  using FeedbackMessage = ca::ParallelGripperCommand_FeedbackMessage_;
  using FeedbackMessageType = ca::ParallelGripperCommand_FeedbackMessage_PubSubType;
  static void set_goal(SendGoalRequest& request, double position, double max_effort) {
    request.goal().command().position({position});
    if (max_effort > 0.0) request.goal().command().effort({max_effort});
  }
};

/// One hand's action, as rclcpp_action's client uses it.
template <typename Types>
class ActionClient {
 public:
  ActionClient(ros2::RosParticipant& participant, const std::string& action)
      : send_goal_(participant, action + "/_action/send_goal"),
        cancel_goal_(participant, action + "/_action/cancel_goal"),
        get_result_(participant, action + "/_action/get_result") {
    feedback_ = participant.reader(
        "rt" + action + "/_action/feedback",
        eprosima::fastdds::dds::TypeSupport(new typename Types::FeedbackMessageType()),
        ros2::RosQos::standard, nullptr);
  }

  /// rclcpp's wait_for_action_server: every service ready.
  bool wait_for_server() {
    const auto deadline = std::chrono::steady_clock::now() + kClientDeadline;
    while (std::chrono::steady_clock::now() < deadline) {
      if (send_goal_.ready() && cancel_goal_.ready() && get_result_.ready()) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
  }

  /// Sends `request` (its goal id set here); whether it was accepted.
  std::optional<bool> send(const Uuid& id, typename Types::SendGoalRequest request) {
    request.goal_id().uuid(id);
    auto reply = send_goal_.call(request, kClientDeadline);
    if (!reply) return std::nullopt;
    return reply->accepted();
  }

  std::optional<bool> send(const Uuid& id, double position, double max_effort) {
    typename Types::SendGoalRequest request;
    Types::set_goal(request, position, max_effort);
    return send(id, request);
  }

  std::optional<typename Types::GetResultResponse> result(const Uuid& id) {
    typename Types::GetResultRequest request;
    request.goal_id().uuid(id);
    return get_result_.call(request, kClientDeadline);
  }

  std::optional<as::CancelGoal_Response_> cancel(const Uuid& id) {
    as::CancelGoal_Request_ request;
    request.goal_info().goal_id().uuid(id);
    return cancel_goal_.call(request, kClientDeadline);
  }

  eprosima::fastdds::dds::DataReader* feedback() { return feedback_; }

 private:
  RosServiceClient<typename Types::SendGoalRequest, typename Types::SendGoalRequestType,
                   typename Types::SendGoalResponse, typename Types::SendGoalResponseType>
      send_goal_;
  RosServiceClient<as::CancelGoal_Request_, as::CancelGoal_Request_PubSubType,
                   as::CancelGoal_Response_, as::CancelGoal_Response_PubSubType>
      cancel_goal_;
  RosServiceClient<typename Types::GetResultRequest, typename Types::GetResultRequestType,
                   typename Types::GetResultResponse, typename Types::GetResultResponseType>
      get_result_;
  eprosima::fastdds::dds::DataReader* feedback_ = nullptr;
};

inline Uuid goal_id(std::uint8_t n) {
  Uuid id{};
  id.fill(n);
  return id;
}

/// The fully qualified name of hand `id`'s `leaf` ("gripper_cmd", "initialize").
inline std::string hand_ros_name(std::uint16_t id, const std::string& leaf) {
  return "/" + test_service_name() + "_bus0_" + std::to_string(id) + "/" + leaf;
}

inline std::string slow_sim_config() {
  std::string config = sim_config();
  const auto at = config.find("position_speed: 400");
  config.replace(at, 19, "position_speed: 50");
  return config;
}

class Ros2ActionFixture : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(service_.started());
    ASSERT_TRUE(ros2_.wait_for_line("dh3-ros2: publishing joint states", kClientDeadline));
    contract::ParticipantOptions options;
    options.domain = test_domain();
    options.name = "ros2_action_client";
    auto made = ros2::RosParticipant::create(options);
    ASSERT_TRUE(made) << made.error();
    participant_ = std::move(made).value();
    ASSERT_TRUE(client_.wait_for_hand(hand_spec(3)));
    ASSERT_TRUE(watcher_.wait_for_hand(hand_spec(3)));
  }

  /// Initializes the hand and waits until the status topic says so, as
  /// dh3-ros2 learns it: a goal is rejected while dh3-ros2 sees the hand not
  /// initialized, and the client that initialized it knows sooner (from the
  /// reply).
  bool initialize_hand(Hand hand) {
    return hand.initialize() && watcher_.hand(hand.address())
                                    .wait_until([](const HandStatus& s) { return s.initialized; })
                                    .has_value();
  }

  /// Initializes the hand and closes it, for a goal that opens it: a move is
  /// answered when the hand takes it, so the goal must start from the closed
  /// hand, far from its target, for feedback to come while it moves.
  bool close_for_goal(Hand hand) {
    return initialize_hand(hand) && hand.move_to(0) &&
           hand.wait_until([](const HandStatus& s) {
                 return s.position == 0 && s.grip != GripState::moving;
               })
               .has_value();
  }

  ActionClient<GripperCommandTypes>& action(std::uint16_t id) {
    auto& slot = actions_[id];
    if (!slot) {
      slot = std::make_unique<ActionClient<GripperCommandTypes>>(*participant_,
                                                                 hand_ros_name(id, "gripper_cmd"));
    }
    return *slot;
  }

  ActionClient<ParallelGripperTypes>& parallel_action(std::uint16_t id) {
    auto& slot = parallel_actions_[id];
    if (!slot) {
      slot = std::make_unique<ActionClient<ParallelGripperTypes>>(
          *participant_, hand_ros_name(id, "parallel_gripper_cmd"));
    }
    return *slot;
  }

  RunningService service_{slow_sim_config()};
  Process ros2_{DH3_ROS2_PATH,
                {"--domain", std::to_string(test_domain()), "--log-level", "debug"},
                Process::Stdin::dev_null};
  Client client_{client_options()};
  Client watcher_{client_options()};  // sends nothing: its statuses are the topic's
  std::unique_ptr<ros2::RosParticipant> participant_;
  std::map<std::uint16_t, std::unique_ptr<ActionClient<GripperCommandTypes>>> actions_;
  std::map<std::uint16_t, std::unique_ptr<ActionClient<ParallelGripperTypes>>> parallel_actions_;
};

}  // namespace dh3::test
