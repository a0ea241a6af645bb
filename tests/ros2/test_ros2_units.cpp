// dh3-ros2's units, ROS names and joint states, as a ROS 2 user sees them.

#include <gtest/gtest.h>

#include <cmath>

#include "hand_services.hpp"
#include "joint_state_message.hpp"
#include "joint_units.hpp"
#include "parallel_gripper_endpoints.hpp"
#include "ros_names.hpp"

namespace dh3::ros2 {
namespace {

TEST(Ros2Units, DefaultsMapPercentToMetersNewtonsAndRadians) {
  const JointUnits units;
  EXPECT_DOUBLE_EQ(units.opening(100), 0.095);
  EXPECT_DOUBLE_EQ(units.opening(0), 0.0);
  EXPECT_DOUBLE_EQ(units.force(50), 45.0);
  EXPECT_DOUBLE_EQ(units.rotation(100), M_PI / 2);
  EXPECT_EQ(units.opening_percent(0.0475), 50);
  EXPECT_EQ(units.force_percent(90.0), 100);
}

TEST(Ros2Units, GoalsOutsideTheRangeOrNaNHaveNoPercent) {
  const JointUnits units;
  EXPECT_FALSE(units.opening_percent(0.2));
  EXPECT_FALSE(units.opening_percent(-0.01));
  EXPECT_FALSE(units.opening_percent(std::nan("")));
  EXPECT_FALSE(units.force_percent(INFINITY));
  EXPECT_FALSE(units.force_percent(120.0));
}

TEST(Ros2Units, PercentModeKeepsTheHandsNumbers) {
  JointUnits units;
  units.raw_percent = true;
  EXPECT_DOUBLE_EQ(units.opening(40), 40.0);
  EXPECT_DOUBLE_EQ(units.rotation(25), 25.0);
  EXPECT_EQ(units.opening_percent(40.0), 40);
}

TEST(Ros2Names, RelativeNamesResolveInTheNamespace) {
  EXPECT_EQ(*resolve_name("/", "joint_states"), "/joint_states");
  EXPECT_EQ(*resolve_name("/cell", "joint_states"), "/cell/joint_states");
  EXPECT_EQ(*resolve_name("/cell", "/joint_states"), "/joint_states");
  EXPECT_EQ(topic_on_dds("/cell/joint_states"), "rt/cell/joint_states");
}

TEST(Ros2Names, NamesBreakingRosRulesAreRefusedWithTheRule) {
  EXPECT_NE(resolve_name("/", "1hand").error().find("digit"), std::string::npos);
  EXPECT_NE(resolve_name("/", "a__b").error().find("__"), std::string::npos);
  EXPECT_NE(resolve_name("/", "a-b").error().find("'-'"), std::string::npos);
  EXPECT_NE(resolve_name("/", "a/").error().find("end"), std::string::npos);
  EXPECT_NE(resolve_name("cell", "a").error().find("namespace"), std::string::npos);
}

TEST(Ros2Names, HandPatternsExpandToNameTokens) {
  EXPECT_EQ(expand_hand_pattern("{service}_{bus}_{id}_finger_joint", {"cell-2", "can0", 7}),
            "cell_2_can0_7_finger_joint");
}

TEST(Ros2JointState, UnreadValuesAreNaNAndEffortFollowsTheGrip) {
  HandStatus status;
  status.address = {"dh3", "bus0", 2};
  status.grip = GripState::moving;
  status.timestamp_ns = 5'000'000'001;
  const auto message = joint_state_of(status, JointNames{}, JointUnits{});
  ASSERT_EQ(message.name().size(), 2U);
  EXPECT_EQ(message.name()[1], "dh3_bus0_2_rotation_joint");
  EXPECT_TRUE(std::isnan(message.position()[0]));
  EXPECT_TRUE(std::isnan(message.position()[1]));
  EXPECT_TRUE(std::isnan(message.effort()[0]));
  EXPECT_TRUE(message.velocity().empty());
  EXPECT_EQ(message.header().stamp().sec(), 5);
  EXPECT_EQ(message.header().stamp().nanosec(), 1U);

  status.grip = GripState::missed;
  status.position = 0;
  EXPECT_EQ(joint_state_of(status, JointNames{}, JointUnits{}).effort()[0], 0.0);
  status.grip = GripState::grasped;
  status.closing_force = 20;
  EXPECT_DOUBLE_EQ(joint_state_of(status, JointNames{}, JointUnits{}).effort()[0], 18.0);
}

rcl_interfaces::msg::dds_::Parameter_ force_parameter(const std::string& name, double newtons) {
  rcl_interfaces::msg::dds_::Parameter_ parameter;
  parameter.name(name);
  parameter.value().type(3);  // PARAMETER_DOUBLE
  parameter.value().double_value(newtons);
  return parameter;
}

TEST(Ros2Forces, ParametersInNewtonsBecomePercentOrSayWhyNot) {
  rcl_interfaces::srv::dds_::SetParameters_Request_ request;
  request.parameters(
      {force_parameter("closing_force", 45.0), force_parameter("opening_force", 90.0)});
  const auto both = forces_of(request, JointUnits{});
  EXPECT_TRUE(both.ok());
  EXPECT_EQ(both.closing, 50);
  EXPECT_EQ(both.opening, 100);
  request.parameters({force_parameter("closing_force", 45.0), force_parameter("closing", 45.0),
                      force_parameter("opening_force", 17.0)});
  const auto refused = forces_of(request, JointUnits{});
  EXPECT_FALSE(refused.ok());
  ASSERT_EQ(refused.refused.size(), 3U);
  EXPECT_EQ(refused.refused[0], "");
  EXPECT_NE(refused.refused[1].find("no parameter closing"), std::string::npos);
  EXPECT_NE(refused.refused[2].find("out of range"), std::string::npos);  // below 20 %
  request.parameters({});
  EXPECT_FALSE(forces_of(request, JointUnits{}).ok()) << "nothing to set is no request";
}

TEST(Ros2ParallelGripper, AGoalIsTheFingerJointsOnePositionAndEffort) {
  sensor_msgs::msg::dds_::JointState_ command;
  command.position({0.02});
  auto goal = ParallelGripperEndpoints::goal_of(command, "f");
  ASSERT_TRUE(goal);
  EXPECT_DOUBLE_EQ(goal->position, 0.02);
  EXPECT_DOUBLE_EQ(goal->max_effort, 0.0);
  command.name({"f"});
  command.effort({30.0});
  goal = ParallelGripperEndpoints::goal_of(command, "f");
  ASSERT_TRUE(goal);
  EXPECT_DOUBLE_EQ(goal->max_effort, 30.0);
  command.name({"g"});
  EXPECT_FALSE(ParallelGripperEndpoints::goal_of(command, "f"));
  command.name({});
  command.position({0.02, 0.02});
  EXPECT_FALSE(ParallelGripperEndpoints::goal_of(command, "f"));
}

}  // namespace
}  // namespace dh3::ros2
