#include "dh3/hand/hand_types.hpp"

namespace dh3::hand {

std::string_view to_string(CommandError error) {
  switch (error) {
    case CommandError::invalid_argument:
      return "invalid argument";
    case CommandError::unknown_hand:
      return "unknown hand";
    case CommandError::timeout:
      return "timeout";
    case CommandError::bus_down:
      return "bus down";
    case CommandError::busy:
      return "busy";
    case CommandError::not_initialized:
      return "not initialized";
    case CommandError::cancelled:
      return "cancelled";
    case CommandError::failed:
      return "failed";
  }
  return "unknown error";
}

std::string_view to_string(CommandKind kind) {
  switch (kind) {
    case CommandKind::initialize:
      return "initialize";
    case CommandKind::move_to:
      return "move";
    case CommandKind::set_closing_force:
      return "set closing force";
    case CommandKind::set_opening_force:
      return "set opening force";
    case CommandKind::rotate_to:
      return "rotate";
    case CommandKind::read_register:
      return "read register";
    case CommandKind::write_register:
      return "write register";
    case CommandKind::grasp:
      return "grasp";
    case CommandKind::release:
      return "release";
    case CommandKind::stop:
      return "stop";
  }
  return "unknown command";
}

std::string_view to_string(GripState state) {
  switch (state) {
    case GripState::unknown:
      return "unknown";
    case GripState::moving:
      return "moving";
    case GripState::arrived:
      return "arrived";
    case GripState::grasped:
      return "grasped";
    case GripState::missed:
      return "missed";
    case GripState::dropped:
      return "dropped";
  }
  return "unknown";
}

std::string_view to_string(RotationState state) {
  switch (state) {
    case RotationState::unknown:
      return "unknown";
    case RotationState::moving:
      return "moving";
    case RotationState::arrived:
      return "arrived";
    case RotationState::blocked:
      return "blocked";
  }
  return "unknown";
}

std::string_view to_string(EventKind kind) {
  switch (kind) {
    case EventKind::online:
      return "online";
    case EventKind::offline:
      return "offline";
    case EventKind::initialized:
      return "initialized";
    case EventKind::init_failed:
      return "initialization failed";
    case EventKind::arrived:
      return "arrived";
    case EventKind::grasped:
      return "grasped";
    case EventKind::missed:
      return "missed";
    case EventKind::dropped:
      return "dropped";
    case EventKind::rotation_arrived:
      return "rotation arrived";
    case EventKind::rotation_blocked:
      return "rotation blocked";
    case EventKind::fault:
      return "fault";
    case EventKind::taken_over:  // the client library's own, never made here
      return "taken over";
  }
  return "unknown";
}

}  // namespace dh3::hand
