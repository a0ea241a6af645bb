// control_msgs/action/GripperCommand and ParallelGripperCommand through
// dh3-ros2 (ros2_action_fixture.hpp), driven by an rmw_fastrtps-style action
// client: goals, feedback, results, a cancel, rejections, and the lease a goal
// holds.

#include <cmath>
#include <limits>

#include "ros2_action_fixture.hpp"

namespace dh3::test {
namespace {

// Each test makes its action clients first, so that matching completes both
// ways while it sets the hand up (test_ros2_hand_services.cpp says why).
using Ros2ActionTest = Ros2ActionFixture;

TEST_F(Ros2ActionTest, AGoalMovesTheHandWithFeedbackAndReachesIt) {
  auto& gripper = action(2);
  auto hand = client_.hand(hand_address(2));
  ASSERT_TRUE(close_for_goal(hand)) << "the hand did not close before the goal";
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
      "rt" + hand_ros_name(2, "gripper_cmd") + "/_action/status",
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
  auto& gripper = action(1);
  ASSERT_TRUE(initialize_hand(client_.hand(hand_address(1))));
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
  auto& gripper = action(3);
  auto hand = client_.hand(hand_address(3));
  ASSERT_TRUE(initialize_hand(hand));
  ASSERT_TRUE(hand.move_to(100));
  ASSERT_TRUE(hand.wait_until([](const HandStatus& s) {
    return s.position == 100 && s.grip != GripState::moving;
  })) << "the hand did not open before the goal";
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
  ASSERT_TRUE(initialize_hand(hand));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(gripper.send(goal_id(5), nan, 0.0), false);
  EXPECT_EQ(gripper.send(goal_id(6), 0.2, 0.0), false);
  EXPECT_EQ(gripper.send(goal_id(7), -0.01, 0.0), false);
  EXPECT_EQ(gripper.send(goal_id(8), 0.05, 10.0), false);  // below 20 % of 90 N
  EXPECT_EQ(gripper.send(goal_id(9), 0.05, nan), false);
  EXPECT_EQ(hand.status()->target_position, -1) << "a rejected goal reached the hand";
  EXPECT_EQ(gripper.result(goal_id(5))->status(), 0);  // unknown: never accepted
}

std::string finger_joint(std::uint16_t id) {
  return test_service_name() + "_bus0_" + std::to_string(id) + "_finger_joint";
}

TEST_F(Ros2ActionTest, AParallelGripperGoalMovesTheFingerJointWithFeedback) {
  auto& gripper = parallel_action(2);
  auto hand = client_.hand(hand_address(2));
  ASSERT_TRUE(close_for_goal(hand)) << "the hand did not close before the goal";
  ASSERT_TRUE(gripper.wait_for_server());
  ca::ParallelGripperCommand_SendGoal_Request_ request;
  request.goal().command().name({finger_joint(2)});
  request.goal().command().position({0.095});
  request.goal().command().effort({45.0});
  ASSERT_EQ(gripper.send(goal_id(11), request), true);
  const auto feedback = wait_for_sample<ca::ParallelGripperCommand_FeedbackMessage_>(
      gripper.feedback(), [](const auto& m) { return m.goal_id().uuid() == goal_id(11); },
      kClientDeadline);
  ASSERT_TRUE(feedback) << "no feedback while the fingers moved";
  EXPECT_EQ(feedback->feedback().state().name(), std::vector<std::string>{finger_joint(2)});
  ASSERT_EQ(feedback->feedback().state().position().size(), 1U);
  EXPECT_EQ(hand.move_to(10).code, Code::denied) << "the goal holds no lease";
  const auto result = gripper.result(goal_id(11));
  ASSERT_TRUE(result);
  EXPECT_EQ(result->status(), kSucceeded);
  EXPECT_TRUE(result->result().reached_goal());
  EXPECT_FALSE(result->result().stalled());
  ASSERT_EQ(result->result().state().position().size(), 1U);
  EXPECT_NEAR(result->result().state().position()[0], 0.095, 1e-9);
  EXPECT_EQ(result->result().state().name(), std::vector<std::string>{finger_joint(2)});
  EXPECT_EQ(hand.status()->closing_force, 50);  // 45 N of 90
  EXPECT_TRUE(hand.wait_until([](const HandStatus& s) { return s.lease_holder.empty(); }))
      << "the goal kept the lease";
}

TEST_F(Ros2ActionTest, AParallelGripperGoalClosingOnAnObjectStalls) {
  auto& gripper = parallel_action(1);
  ASSERT_TRUE(initialize_hand(client_.hand(hand_address(1))));
  ASSERT_TRUE(gripper.wait_for_server());
  ASSERT_EQ(gripper.send(goal_id(12), 0.0, 0.0), true);  // no effort: the hand's force
  const auto result = gripper.result(goal_id(12));
  ASSERT_TRUE(result);
  EXPECT_EQ(result->status(), kSucceeded);
  EXPECT_TRUE(result->result().stalled());
  EXPECT_FALSE(result->result().reached_goal());
  ASSERT_EQ(result->result().state().position().size(), 1U);
  EXPECT_NEAR(result->result().state().position()[0], 0.038, 0.002);  // the object at 40 %
  ASSERT_EQ(result->result().state().effort().size(), 1U);
  EXPECT_GT(result->result().state().effort()[0], 0.0);
}

TEST_F(Ros2ActionTest, ParallelGripperGoalsNotForTheFingerJointAreRejected) {
  auto& gripper = parallel_action(3);
  auto hand = client_.hand(hand_address(3));
  ASSERT_TRUE(initialize_hand(hand));
  ASSERT_TRUE(gripper.wait_for_server());
  ca::ParallelGripperCommand_SendGoal_Request_ two;
  two.goal().command().position({0.02, 0.02});
  EXPECT_EQ(gripper.send(goal_id(13), two), false);
  ca::ParallelGripperCommand_SendGoal_Request_ none;
  EXPECT_EQ(gripper.send(goal_id(14), none), false);
  ca::ParallelGripperCommand_SendGoal_Request_ other;
  other.goal().command().name({finger_joint(2)});
  other.goal().command().position({0.02});
  EXPECT_EQ(gripper.send(goal_id(15), other), false);
  EXPECT_EQ(gripper.send(goal_id(16), 0.2, 0.0), false);    // beyond 0.095 m
  EXPECT_EQ(gripper.send(goal_id(17), 0.05, 10.0), false);  // below 20 % of 90 N
  EXPECT_EQ(hand.status()->target_position, -1) << "a rejected goal reached the hand";
}

TEST_F(Ros2ActionTest, AGoalOfTheOtherActionPreemptsTheOneRunning) {
  auto& gripper = action(3);
  auto& parallel = parallel_action(3);
  auto hand = client_.hand(hand_address(3));
  ASSERT_TRUE(initialize_hand(hand));
  ASSERT_TRUE(hand.move_to(100));
  ASSERT_TRUE(hand.wait_until([](const HandStatus& s) {
    return s.position == 100 && s.grip != GripState::moving;
  })) << "the hand did not open before the goals";
  ASSERT_TRUE(gripper.wait_for_server());
  ASSERT_TRUE(parallel.wait_for_server());
  ASSERT_EQ(gripper.send(goal_id(18), 0.0, 0.0), true);
  ASSERT_TRUE(hand.wait_until([](const HandStatus& s) { return s.grip == GripState::moving; }))
      << "the first goal did not move the hand";
  ASSERT_EQ(parallel.send(goal_id(19), 0.095, 0.0), true);
  const auto first = gripper.result(goal_id(18));
  ASSERT_TRUE(first);
  EXPECT_EQ(first->status(), kCanceled);
  const auto second = parallel.result(goal_id(19));
  ASSERT_TRUE(second);
  EXPECT_EQ(second->status(), kSucceeded);
  EXPECT_TRUE(second->result().reached_goal());
}

}  // namespace
}  // namespace dh3::test
