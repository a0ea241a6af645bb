#include "conversions.hpp"

#include <chrono>

#include "dh3/protocol/registers.hpp"

namespace dh3::dds {

msg::ResultCode to_result_code(hand::CommandError error) {
  using hand::CommandError;
  switch (error) {
    case CommandError::invalid_argument:
      return msg::INVALID_ARGUMENT;
    case CommandError::unknown_hand:
      return msg::UNKNOWN_HAND;
    case CommandError::timeout:
      return msg::TIMEOUT;
    case CommandError::bus_down:
      return msg::BUS_DOWN;
    case CommandError::busy:
      return msg::BUSY;
    case CommandError::not_initialized:
      return msg::NOT_INITIALIZED;
    case CommandError::cancelled:
      return msg::CANCELLED;
    case CommandError::failed:
      return msg::FAILED;
  }
  return msg::FAILED;
}

msg::GraspOutcome to_msg(hand::GraspOutcome outcome) {
  switch (outcome) {
    case hand::GraspOutcome::none:
      return msg::GRASP_NONE;
    case hand::GraspOutcome::grasped:
      return msg::GRASPED;
    case hand::GraspOutcome::missed:
      return msg::MISSED;
  }
  return msg::GRASP_NONE;
}

msg::GripState to_msg(hand::GripState state) {
  switch (state) {
    case hand::GripState::unknown:
      return msg::GRIP_UNKNOWN;
    case hand::GripState::moving:
      return msg::GRIP_MOVING;
    case hand::GripState::arrived:
      return msg::GRIP_ARRIVED;
    case hand::GripState::grasped:
      return msg::GRIP_GRASPED;
    case hand::GripState::missed:
      return msg::GRIP_MISSED;
    case hand::GripState::dropped:
      return msg::GRIP_DROPPED;
  }
  return msg::GRIP_UNKNOWN;
}

msg::RotationState to_msg(hand::RotationState state) {
  switch (state) {
    case hand::RotationState::unknown:
      return msg::ROTATION_UNKNOWN;
    case hand::RotationState::moving:
      return msg::ROTATION_MOVING;
    case hand::RotationState::arrived:
      return msg::ROTATION_ARRIVED;
    case hand::RotationState::blocked:
      return msg::ROTATION_BLOCKED;
  }
  return msg::ROTATION_UNKNOWN;
}

msg::EventKind to_msg(hand::EventKind kind) {
  using hand::EventKind;
  switch (kind) {
    case EventKind::online:
      return msg::EVENT_ONLINE;
    case EventKind::offline:
      return msg::EVENT_OFFLINE;
    case EventKind::initialized:
      return msg::EVENT_INITIALIZED;
    case EventKind::init_failed:
      return msg::EVENT_INIT_FAILED;
    case EventKind::arrived:
      return msg::EVENT_ARRIVED;
    case EventKind::grasped:
      return msg::EVENT_GRASPED;
    case EventKind::missed:
      return msg::EVENT_MISSED;
    case EventKind::dropped:
      return msg::EVENT_DROPPED;
    case EventKind::rotation_arrived:
      return msg::EVENT_ROTATION_ARRIVED;
    case EventKind::rotation_blocked:
      return msg::EVENT_ROTATION_BLOCKED;
    case EventKind::fault:
    case EventKind::taken_over:  // the client library's own, never made by the hand layer
      return msg::EVENT_FAULT;
  }
  return msg::EVENT_FAULT;
}

bool is_valid_command(msg::CommandType command) {
  return static_cast<std::uint32_t>(command) <= static_cast<std::uint32_t>(msg::RELEASE_LEASE);
}

std::string hand_text(std::string_view bus, std::uint8_t can_id) {
  return "hand " + std::to_string(can_id) + " on bus '" + std::string(bus) + "'";
}

std::string describe_failure(hand::CommandError error, msg::CommandType command,
                             std::string_view bus, std::uint8_t can_id) {
  const std::string what = command_name(command);
  const std::string hand = "hand " + std::to_string(can_id) + " on bus '" + std::string(bus) + "'";
  switch (error) {
    case hand::CommandError::invalid_argument:
      return what + " rejected by the hand layer as invalid for " + hand;
    case hand::CommandError::unknown_hand:
      return "no " + hand;
    case hand::CommandError::timeout:
      return hand + " did not answer " + what + " in time";
    case hand::CommandError::bus_down:
      return "bus '" + std::string(bus) + "' is down";
    case hand::CommandError::busy:
      return hand + " has too many commands waiting; " + what + " was not queued";
    case hand::CommandError::not_initialized:
      return hand + " is not initialized; send INITIALIZE before " + what;
    case hand::CommandError::cancelled:
      return what + " to " + hand + " was cancelled (superseded, stopped, or shutdown)";
    case hand::CommandError::failed:
      return hand + " answered, but " + what + " did not succeed";
  }
  return what + " failed";
}

void fill_status(msg::HandStatus& out, const hand::HandState& state, const StatusContext& context) {
  out.service(std::string(context.service));
  out.bus(std::string(context.bus));
  out.can_id(state.can_id);
  out.name(state.name);
  out.online(state.online);
  out.initialized(state.initialized);
  out.grip(to_msg(state.grip));
  out.position(state.position);
  out.target_position(state.target_position);
  out.closing_force(state.closing_force);
  out.opening_force(state.opening_force);
  out.rotation(state.rotation);
  out.rotation_target(state.rotation_target);
  out.rotation_state(to_msg(state.rotation_state));
  out.firmware_version(state.firmware_version);
  out.firmware_version_text(state.firmware_version != 0
                                ? protocol::firmware_version_string(state.firmware_version)
                                : std::string{});
  out.last_error(state.last_error ? to_result_code(*state.last_error) : msg::OK);
  out.last_error_message(state.last_error_message);
  out.lease_holder(std::string(context.lease_holder));
  out.timestamp_ns(context.timestamp_ns);
  out.update_seq(context.update_seq);
  out.read_at_ns(context.read_at_ns);
}

void fill_event(msg::HandEvent& out, const hand::HandEvent& event, std::string_view service,
                std::string_view bus, std::string_view hand_name, std::uint64_t event_seq,
                std::uint64_t timestamp_ns) {
  out.hand().service(std::string(service));
  out.hand().bus(std::string(bus));
  out.hand().can_id(event.can_id);
  out.name(std::string(hand_name));
  out.kind(to_msg(event.kind));
  out.position(event.position.value_or(-1));
  out.position_known(event.position.has_value());
  out.target(event.target);
  out.value(event.value);
  out.message(event.message);
  out.timestamp_ns(timestamp_ns);
  out.event_seq(event_seq);
}

std::uint64_t wall_clock_ns() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

}  // namespace dh3::dds
