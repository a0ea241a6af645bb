// What a value of the two status registers means, given what the driver knows:
// every case of status_reading.hpp, one table row each.

#include <gtest/gtest.h>

#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "status_reading.hpp"

namespace dh3::hand {
namespace {

constexpr std::int32_t kMoving = 0;
constexpr std::int32_t kArrived = 2;
constexpr std::int32_t kCaught = 3;

/// Closing to 10 from further open; a plain move (not a grasp).
constexpr FingerMotion kClosingMove{.target = 10, .gripping = false, .closing = true};
/// A grasp: closing to 0, ending without a catch is a miss.
constexpr FingerMotion kGrasp{.target = 0, .gripping = true, .closing = true};
/// Opening to 90.
constexpr FingerMotion kOpening{.target = 90, .gripping = false, .closing = false};

struct GripCase {
  std::string name;
  std::int32_t status;
  FingerView view;
  GripReading expected;
};

GripReading ends(GripState grip, EventKind event) {
  return GripReading{.grip = grip, .event = event, .motion_ended = true};
}

std::vector<GripCase> grip_cases() {
  using G = GripState;
  using E = EventKind;
  GripReading caught_ends = ends(G::grasped, E::grasped);
  caught_ends.hold_starts = true;
  return {
      // status 3
      {"caught_while_closing_is_a_grasp",
       kCaught,
       {G::moving, kClosingMove, false, 40, 0},
       caught_ends},
      {"caught_during_a_grasp_is_a_grasp", kCaught, {G::moving, kGrasp, false, 40, 0}, caught_ends},
      {"caught_while_opening_is_stale",
       kCaught,
       {G::moving, kOpening, false, 40, 0},
       GripReading{.stale = true}},
      {"caught_at_rest_starts_a_hold",
       kCaught,
       {G::arrived, std::nullopt, false, 40, 0},
       GripReading{.grip = G::grasped, .hold_starts = true}},
      {"caught_again_while_holding_keeps_the_hold",
       kCaught,
       {G::grasped, std::nullopt, true, 40, 0},
       GripReading{.grip = G::grasped, .hold_starts = true}},
      // drops
      {"arrived_while_holding_untouched_is_a_drop",
       kArrived,
       {G::grasped, std::nullopt, true, 40, 0},
       GripReading{.grip = G::dropped, .event = E::dropped}},
      {"moving_while_holding_untouched_is_a_drop",
       kMoving,
       {G::grasped, std::nullopt, true, 40, 0},
       GripReading{.grip = G::dropped, .event = E::dropped}},
      {"after_a_drop_nothing_changes",
       kArrived,
       {G::dropped, std::nullopt, true, 40, 0},
       GripReading{}},
      {"caught_then_commanded_is_no_drop",
       kArrived,
       {G::grasped, kOpening, false, 89, 0},
       ends(G::arrived, E::arrived)},
      // status 2
      {"arrived_near_the_target_ends_a_move",
       kArrived,
       {G::moving, kClosingMove, false, 12, 0},
       ends(G::arrived, E::arrived)},
      {"arrived_far_from_the_target_is_stale",
       kArrived,
       {G::moving, kClosingMove, false, 40, 0},
       GripReading{.stale = true}},
      {"arrived_with_the_position_unknown_ends_a_move",
       kArrived,
       {G::moving, kClosingMove, false, -1, 0},
       ends(G::arrived, E::arrived)},
      {"arrived_at_the_end_of_a_grasp_is_a_miss",
       kArrived,
       {G::moving, kGrasp, false, 0, 0},
       ends(G::missed, E::missed)},
      {"arrived_at_rest_says_arrived",
       kArrived,
       {G::unknown, std::nullopt, false, 50, 0},
       GripReading{.grip = G::arrived}},
      {"arrived_at_rest_after_a_miss_stays_a_miss",
       kArrived,
       {G::missed, std::nullopt, false, 0, 0},
       GripReading{}},
      // status 0
      {"moving_during_a_motion_says_moving",
       kMoving,
       {G::arrived, kClosingMove, false, 40, 0},
       GripReading{.grip = G::moving}},
      {"moving_at_rest_is_the_default",
       kMoving,
       {G::arrived, std::nullopt, false, 40, 0},
       GripReading{}},
      // outside the document
      {"an_undefined_value_is_a_fault",
       7,
       {G::arrived, std::nullopt, false, 40, 0},
       GripReading{.event = E::fault}},
      {"the_same_undefined_value_again_is_not",
       7,
       {G::arrived, std::nullopt, false, 40, 7},
       GripReading{}},
      {"another_undefined_value_is_a_fault",
       9,
       {G::arrived, std::nullopt, false, 40, 7},
       GripReading{.event = E::fault}},
  };
}

void PrintTo(const GripCase& c, std::ostream* out) {
  *out << c.name;
}

class GripStatusReading : public ::testing::TestWithParam<GripCase> {};

TEST_P(GripStatusReading, MeansWhatTheTableSays) {
  const GripCase& c = GetParam();
  const GripReading got = read_grip_status(c.status, c.view);
  EXPECT_EQ(got.grip, c.expected.grip);
  EXPECT_EQ(got.event, c.expected.event);
  EXPECT_EQ(got.motion_ended, c.expected.motion_ended);
  EXPECT_EQ(got.hold_starts, c.expected.hold_starts);
  EXPECT_EQ(got.stale, c.expected.stale);
}

INSTANTIATE_TEST_SUITE_P(Cases, GripStatusReading, ::testing::ValuesIn(grip_cases()),
                         [](const auto& test_case) { return test_case.param.name; });

struct RotationCase {
  std::string name;
  std::int32_t status;
  RotationView view;
  RotationReading expected;
};

std::vector<RotationCase> rotation_cases() {
  using R = RotationState;
  using E = EventKind;
  const RotationMotion to_80{80};
  return {
      {"moving_during_a_rotation", kMoving, {to_80, 40, 0}, RotationReading{.state = R::moving}},
      {"moving_at_rest_is_the_default", kMoving, {std::nullopt, 40, 0}, RotationReading{}},
      {"arrived_near_the_target_ends_the_rotation",
       kArrived,
       {to_80, 78, 0},
       RotationReading{.state = R::arrived, .event = E::rotation_arrived, .motion_ended = true}},
      {"arrived_far_from_the_target_is_stale",
       kArrived,
       {to_80, 40, 0},
       RotationReading{.stale = true}},
      {"arrived_at_rest_says_arrived",
       kArrived,
       {std::nullopt, 40, 0},
       RotationReading{.state = R::arrived}},
      {"blocked_during_a_rotation_ends_it",
       3,
       {to_80, 40, 0},
       RotationReading{.state = R::blocked, .event = E::rotation_blocked, .motion_ended = true}},
      {"blocked_at_rest_says_blocked",
       3,
       {std::nullopt, 40, 0},
       RotationReading{.state = R::blocked}},
      {"an_undefined_value_is_a_fault",
       7,
       {std::nullopt, 40, 0},
       RotationReading{.event = E::fault}},
      {"the_same_undefined_value_again_is_not", 7, {std::nullopt, 40, 7}, RotationReading{}},
  };
}

void PrintTo(const RotationCase& c, std::ostream* out) {
  *out << c.name;
}

class RotationStatusReading : public ::testing::TestWithParam<RotationCase> {};

TEST_P(RotationStatusReading, MeansWhatTheTableSays) {
  const RotationCase& c = GetParam();
  const RotationReading got = read_rotation_status(c.status, c.view);
  EXPECT_EQ(got.state, c.expected.state);
  EXPECT_EQ(got.event, c.expected.event);
  EXPECT_EQ(got.motion_ended, c.expected.motion_ended);
  EXPECT_EQ(got.stale, c.expected.stale);
}

INSTANTIATE_TEST_SUITE_P(Cases, RotationStatusReading, ::testing::ValuesIn(rotation_cases()),
                         [](const auto& test_case) { return test_case.param.name; });

}  // namespace
}  // namespace dh3::hand
