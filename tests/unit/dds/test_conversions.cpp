#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "conversions.hpp"

namespace dh3::dds {
namespace {

using ::testing::HasSubstr;

TEST(Conversions, EveryCommandErrorHasItsResultCode) {
  using hand::CommandError;
  EXPECT_EQ(to_result_code(CommandError::invalid_argument), msg::INVALID_ARGUMENT);
  EXPECT_EQ(to_result_code(CommandError::unknown_hand), msg::UNKNOWN_HAND);
  EXPECT_EQ(to_result_code(CommandError::timeout), msg::TIMEOUT);
  EXPECT_EQ(to_result_code(CommandError::bus_down), msg::BUS_DOWN);
  EXPECT_EQ(to_result_code(CommandError::busy), msg::BUSY);
  EXPECT_EQ(to_result_code(CommandError::not_initialized), msg::NOT_INITIALIZED);
  EXPECT_EQ(to_result_code(CommandError::cancelled), msg::CANCELLED);
  EXPECT_EQ(to_result_code(CommandError::failed), msg::FAILED);
}

TEST(Conversions, FailureMessagesNameTheHandAndCommand) {
  EXPECT_THAT(describe_failure(hand::CommandError::timeout, msg::MOVE, "left", 2),
              HasSubstr("hand 2 on bus 'left' did not answer MOVE"));
  EXPECT_THAT(describe_failure(hand::CommandError::not_initialized, msg::GRASP, "bus0", 1),
              HasSubstr("INITIALIZE"));
  EXPECT_THAT(describe_failure(hand::CommandError::bus_down, msg::ROTATE, "bus0", 1),
              HasSubstr("bus 'bus0' is down"));
  for (int e = 0; e <= static_cast<int>(hand::CommandError::failed); ++e) {
    EXPECT_FALSE(
        describe_failure(static_cast<hand::CommandError>(e), msg::STOP, "bus0", 1).empty());
  }
}

TEST(Conversions, CommandNamesCoverTheEnumAndBeyond) {
  EXPECT_EQ(command_name(msg::READ_REGISTER), "READ_REGISTER");
  EXPECT_EQ(command_name(msg::RELEASE_LEASE), "RELEASE_LEASE");
  EXPECT_EQ(command_name(static_cast<msg::CommandType>(42)), "command 42");
  EXPECT_TRUE(is_valid_command(msg::RELEASE_LEASE));
  EXPECT_FALSE(is_valid_command(static_cast<msg::CommandType>(16)));
  EXPECT_EQ(result_code_name(msg::DENIED), "DENIED");
}

TEST(Conversions, StatusCarriesTheHandStateAndTheServicesAdditions) {
  hand::HandState state;
  state.can_id = 3;
  state.name = "left";
  state.online = true;
  state.initialized = true;
  state.grip = hand::GripState::grasped;
  state.position = 40;
  state.target_position = 0;
  state.closing_force = 30;
  state.opening_force = 60;
  state.rotation = 50;
  state.rotation_target = 67;
  state.rotation_state = hand::RotationState::blocked;
  state.firmware_version = 0x04010200;
  state.last_error = hand::CommandError::timeout;
  state.last_error_message = "no answer";

  msg::HandStatus out;
  fill_status(out, state, StatusContext{"dh3", "bus0", "abc", 12, 1234, 1200});
  EXPECT_EQ(out.service(), "dh3");
  EXPECT_EQ(out.bus(), "bus0");
  EXPECT_EQ(out.can_id(), 3);
  EXPECT_EQ(out.name(), "left");
  EXPECT_TRUE(out.online());
  EXPECT_TRUE(out.initialized());
  EXPECT_EQ(out.grip(), msg::GRIP_GRASPED);
  EXPECT_EQ(out.position(), 40);
  EXPECT_EQ(out.target_position(), 0);
  EXPECT_EQ(out.closing_force(), 30);
  EXPECT_EQ(out.opening_force(), 60);
  EXPECT_EQ(out.rotation(), 50);
  EXPECT_EQ(out.rotation_target(), 67);
  EXPECT_EQ(out.rotation_state(), msg::ROTATION_BLOCKED);
  EXPECT_EQ(out.firmware_version(), 0x04010200);
  EXPECT_EQ(out.firmware_version_text(), "4.1.2.0");
  EXPECT_EQ(out.last_error(), msg::TIMEOUT);
  EXPECT_EQ(out.last_error_message(), "no answer");
  EXPECT_EQ(out.lease_holder(), "abc");
  EXPECT_EQ(out.update_seq(), 12U);
  EXPECT_EQ(out.timestamp_ns(), 1234U);
  EXPECT_EQ(out.read_at_ns(), 1200U);

  // Reusing the sample leaves nothing of the previous hand behind.
  fill_status(out, hand::HandState{}, StatusContext{"dh3", "bus0", "", 13, 1235});
  EXPECT_EQ(out.name(), "");
  EXPECT_EQ(out.lease_holder(), "");
  EXPECT_EQ(out.read_at_ns(), 0U);  // never answered
  EXPECT_EQ(out.firmware_version_text(), "");
  EXPECT_EQ(out.last_error(), msg::OK);
  EXPECT_EQ(out.grip(), msg::GRIP_UNKNOWN);
  EXPECT_EQ(out.position(), -1);
}

TEST(Conversions, EventsKeepTheirKindAndNumbers) {
  hand::HandEvent event;
  event.kind = hand::EventKind::dropped;
  event.can_id = 2;
  event.position = 70;
  event.target = 0;
  event.value = 2;
  event.message = "object lost";
  msg::HandEvent out;
  fill_event(out, event, "dh3", "bus1", "right", 5, 99);
  EXPECT_EQ(out.hand().service(), "dh3");
  EXPECT_EQ(out.hand().bus(), "bus1");
  EXPECT_EQ(out.hand().can_id(), 2);
  EXPECT_EQ(out.name(), "right");
  EXPECT_EQ(out.kind(), msg::EVENT_DROPPED);
  EXPECT_EQ(out.position(), 70);
  EXPECT_TRUE(out.position_known());
  EXPECT_EQ(out.target(), 0);
  EXPECT_EQ(out.value(), 2);
  EXPECT_EQ(out.message(), "object lost");
  EXPECT_EQ(out.event_seq(), 5U);
  EXPECT_EQ(out.timestamp_ns(), 99U);
  event.kind = hand::EventKind::arrived;
  event.position.reset();
  fill_event(out, event, "dh3", "bus1", "right", 6, 100);
  EXPECT_FALSE(out.position_known()) << "an arrival whose stop was not read yet says so";
  EXPECT_EQ(out.position(), -1);
}

TEST(Conversions, EnumsMapOneToOne) {
  EXPECT_EQ(to_msg(hand::GraspOutcome::grasped), msg::GRASPED);
  EXPECT_EQ(to_msg(hand::GraspOutcome::missed), msg::MISSED);
  EXPECT_EQ(to_msg(hand::GraspOutcome::none), msg::GRASP_NONE);
  EXPECT_EQ(to_msg(hand::GripState::missed), msg::GRIP_MISSED);
  EXPECT_EQ(to_msg(hand::GripState::dropped), msg::GRIP_DROPPED);
  EXPECT_EQ(to_msg(hand::RotationState::arrived), msg::ROTATION_ARRIVED);
  EXPECT_EQ(to_msg(hand::EventKind::online), msg::EVENT_ONLINE);
  EXPECT_EQ(to_msg(hand::EventKind::rotation_blocked), msg::EVENT_ROTATION_BLOCKED);
  EXPECT_EQ(to_msg(hand::EventKind::fault), msg::EVENT_FAULT);
}

}  // namespace
}  // namespace dh3::dds
