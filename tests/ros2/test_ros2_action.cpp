// control_msgs/action/GripperCommand through dh3-ros2, beside dh3-service on
// the simulator (hand 1 has an object at 40 %; fingers move 50 %/s so a goal
// can be cancelled while it moves), driven by an rmw_fastrtps-style action
// client (ros_action_client.hpp): goals, feedback, results, a cancel,
// rejections, and the lease a goal holds.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "integration/client/client_fixture.hpp"
#include "ros2_interfacesPubSubTypes.h"
#include "ros_action_client.hpp"

namespace dh3::test {
namespace {

namespace ca = control_msgs::action::dds_;
namespace as = action_msgs::srv::dds_;
using Uuid = std::array<std::uint8_t, 16>;
using SendGoal = RosServiceClient<
    ca::GripperCommand_SendGoal_Request_, ca::GripperCommand_SendGoal_Request_PubSubType,
    ca::GripperCommand_SendGoal_Response_, ca::GripperCommand_SendGoal_Response_PubSubType>;
using CancelGoal = RosServiceClient<as::CancelGoal_Request_, as::CancelGoal_Request_PubSubType,
                                    as::CancelGoal_Response_, as::CancelGoal_Response_PubSubType>;
using GetResult = RosServiceClient<
    ca::GripperCommand_GetResult_Request_, ca::GripperCommand_GetResult_Request_PubSubType,
    ca::GripperCommand_GetResult_Response_, ca::GripperCommand_GetResult_Response_PubSubType>;

constexpr std::int8_t kSucceeded = 4;
constexpr std::int8_t kCanceled = 5;

std::string slow_sim_config() {
  std::string config = sim_config();
  const auto at = config.find("position_speed: 400");
  config.replace(at, 19, "position_speed: 50");
  return config;
}

/// One hand's action, as rclcpp_action's client uses it.
class ActionClient {
 public:
  ActionClient(ros2::RosParticipant& participant, const std::string& action)
      : send_goal_(participant, action + "/_action/send_goal"),
        cancel_goal_(participant, action + "/_action/cancel_goal"),
        get_result_(participant, action + "/_action/get_result") {
    feedback_ = participant.reader(
        "rt" + action + "/_action/feedback",
        eprosima::fastdds::dds::TypeSupport(new ca::GripperCommand_FeedbackMessage_PubSubType()),
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

  std::optional<bool> send(const Uuid& id, double position, double max_effort) {
    ca::GripperCommand_SendGoal_Request_ request;
    request.goal_id().uuid(id);
    request.goal().command().position(position);
    request.goal().command().max_effort(max_effort);
    auto reply = send_goal_.call(request, kClientDeadline);
    if (!reply) return std::nullopt;
    return reply->accepted();
  }

  std::optional<ca::GripperCommand_GetResult_Response_> result(const Uuid& id) {
    ca::GripperCommand_GetResult_Request_ request;
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
  SendGoal send_goal_;
  CancelGoal cancel_goal_;
  GetResult get_result_;
  eprosima::fastdds::dds::DataReader* feedback_ = nullptr;
};

Uuid goal_id(std::uint8_t n) {
  Uuid id{};
  id.fill(n);
  return id;
}

std::string action_of(std::uint16_t id) {
  return "/" + test_service_name() + "_bus0_" + std::to_string(id) + "/gripper_cmd";
}

class Ros2ActionTest : public ::testing::Test {
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
  }

  ActionClient& action(std::uint16_t id) {
    auto& slot = actions_[id];
    if (!slot) slot = std::make_unique<ActionClient>(*participant_, action_of(id));
    return *slot;
  }

  RunningService service_{slow_sim_config()};
  Process ros2_{DH3_ROS2_PATH,
                {"--domain", std::to_string(test_domain()), "--log-level", "debug"},
                Process::Stdin::dev_null};
  Client client_{client_options()};
  std::unique_ptr<ros2::RosParticipant> participant_;
  std::map<std::uint16_t, std::unique_ptr<ActionClient>> actions_;
};

TEST_F(Ros2ActionTest, AGoalMovesTheHandWithFeedbackAndReachesIt) {
  auto hand = client_.hand(hand_address(2));
  ASSERT_TRUE(hand.initialize());
  // A move is answered when the hand takes it: the goal must start from the
  // closed hand, far from its target, for feedback to come while it moves.
  ASSERT_TRUE(hand.move_to(0));
  ASSERT_TRUE(hand.wait_until([](const HandStatus& s) {
    return s.position == 0 && s.grip != GripState::moving;
  })) << "the hand did not close before the goal";
  auto& gripper = action(2);
  ASSERT_TRUE(gripper.wait_for_server());
  ASSERT_EQ(gripper.send(goal_id(1), 0.095, 45.0), true);
  EXPECT_TRUE(wait_for_sample<ca::GripperCommand_FeedbackMessage_>(
      gripper.feedback(), [](const auto& m) { return m.goal_id().uuid() == goal_id(1); },
      kClientDeadline))
      << "no feedback while the fingers moved";
  // Meanwhile the goal holds the hand's lease: another client is refused.
  EXPECT_EQ(hand.move_to(10).code, Code::denied);
  const auto result = gripper.result(goal_id(1));
  ASSERT_TRUE(result);
  EXPECT_EQ(result->status(), kSucceeded);
  EXPECT_TRUE(result->result().reached_goal());
  EXPECT_FALSE(result->result().stalled());
  EXPECT_NEAR(result->result().position(), 0.095, 1e-9);
  EXPECT_EQ(hand.status()->closing_force, 50);  // 45 N of 90
  EXPECT_TRUE(hand.wait_until([](const HandStatus& s) { return s.lease_holder.empty(); }))
      << "the goal kept the lease";
  EXPECT_TRUE(hand.move_to(100));

  // A status reader that joins now gets the goal's end (TRANSIENT_LOCAL, depth 1).
  auto* status = participant_->reader(
      "rt" + action_of(2) + "/_action/status",
      eprosima::fastdds::dds::TypeSupport(new action_msgs::msg::dds_::GoalStatusArray_PubSubType()),
      ros2::RosQos::action_status, nullptr);
  ASSERT_NE(status, nullptr);
  EXPECT_TRUE(wait_for_sample<action_msgs::msg::dds_::GoalStatusArray_>(
      status,
      [](const auto& array) {
        return array.status_list().size() == 1 &&
               array.status_list()[0].goal_info().goal_id().uuid() == goal_id(1) &&
               array.status_list()[0].status() == kSucceeded;
      },
      kClientDeadline))
      << "a late status reader did not get the succeeded goal";
}

TEST_F(Ros2ActionTest, ClosingOnAnObjectStalls) {
  ASSERT_TRUE(client_.hand(hand_address(1)).initialize());
  auto& gripper = action(1);
  ASSERT_TRUE(gripper.wait_for_server());
  ASSERT_EQ(gripper.send(goal_id(2), 0.0, 0.0), true);
  const auto result = gripper.result(goal_id(2));
  ASSERT_TRUE(result);
  EXPECT_EQ(result->status(), kSucceeded);
  EXPECT_TRUE(result->result().stalled());
  EXPECT_FALSE(result->result().reached_goal());
  EXPECT_NEAR(result->result().position(), 0.038, 0.002);  // the object at 40 %
  EXPECT_GT(result->result().effort(), 0.0);
}

TEST_F(Ros2ActionTest, ACancelStopsTheHand) {
  auto hand = client_.hand(hand_address(3));
  ASSERT_TRUE(hand.initialize());
  ASSERT_TRUE(hand.move_to(100));
  ASSERT_TRUE(hand.wait_until([](const HandStatus& s) {
    return s.position == 100 && s.grip != GripState::moving;
  })) << "the hand did not open before the goal";
  auto& gripper = action(3);
  ASSERT_TRUE(gripper.wait_for_server());
  ASSERT_EQ(gripper.send(goal_id(3), 0.0, 0.0), true);
  const auto cancel = gripper.cancel(goal_id(3));
  ASSERT_TRUE(cancel);
  EXPECT_EQ(cancel->return_code(), 0);
  ASSERT_EQ(cancel->goals_canceling().size(), 1U);
  EXPECT_EQ(cancel->goals_canceling()[0].goal_id().uuid(), goal_id(3));
  const auto result = gripper.result(goal_id(3));
  ASSERT_TRUE(result);
  EXPECT_EQ(result->status(), kCanceled);
  const auto stopped = hand.wait_until([](const HandStatus& s) {
    return s.grip != GripState::moving && s.position > 0 && s.lease_holder.empty();
  });
  ASSERT_TRUE(stopped);
  EXPECT_GT(stopped->position, 0) << "the fingers closed anyway";
}

TEST_F(Ros2ActionTest, GoalsOutOfRangeOrForAHandNotReadyAreRejected) {
  auto& gripper = action(3);  // not initialized
  ASSERT_TRUE(gripper.wait_for_server());
  EXPECT_EQ(gripper.send(goal_id(4), 0.05, 0.0), false);
  auto hand = client_.hand(hand_address(3));
  ASSERT_TRUE(hand.initialize());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(gripper.send(goal_id(5), nan, 0.0), false);
  EXPECT_EQ(gripper.send(goal_id(6), 0.2, 0.0), false);
  EXPECT_EQ(gripper.send(goal_id(7), -0.01, 0.0), false);
  EXPECT_EQ(gripper.send(goal_id(8), 0.05, 10.0), false);  // below 20 % of 90 N
  EXPECT_EQ(gripper.send(goal_id(9), 0.05, nan), false);
  EXPECT_EQ(hand.status()->target_position, -1) << "a rejected goal reached the hand";
  EXPECT_EQ(gripper.result(goal_id(5))->status(), 0);  // unknown: never accepted
}

}  // namespace
}  // namespace dh3::test
