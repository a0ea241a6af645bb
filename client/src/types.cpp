#include "dh3/types.hpp"

namespace dh3 {

std::string_view to_string(Code code) {
  switch (code) {
    case Code::ok:
      return "OK";
    case Code::invalid_argument:
      return "INVALID_ARGUMENT";
    case Code::unknown_hand:
      return "UNKNOWN_HAND";
    case Code::timeout:
      return "TIMEOUT";
    case Code::bus_down:
      return "BUS_DOWN";
    case Code::busy:
      return "BUSY";
    case Code::not_initialized:
      return "NOT_INITIALIZED";
    case Code::denied:
      return "DENIED";
    case Code::cancelled:
      return "CANCELLED";
    case Code::failed:
      return "FAILED";
    case Code::no_service:
      return "NO_SERVICE";
    case Code::no_reply:
      return "NO_REPLY";
    case Code::service_lost:
      return "SERVICE_LOST";
    case Code::not_connected:
      return "NOT_CONNECTED";
  }
  return "UNKNOWN";
}

std::string_view to_string(GraspOutcome outcome) {
  switch (outcome) {
    case GraspOutcome::none:
      return "NONE";
    case GraspOutcome::grasped:
      return "GRASPED";
    case GraspOutcome::missed:
      return "MISSED";
  }
  return "NONE";
}

std::string_view to_string(GripState state) {
  switch (state) {
    case GripState::unknown:
      return "UNKNOWN";
    case GripState::moving:
      return "MOVING";
    case GripState::arrived:
      return "ARRIVED";
    case GripState::grasped:
      return "GRASPED";
    case GripState::missed:
      return "MISSED";
    case GripState::dropped:
      return "DROPPED";
  }
  return "UNKNOWN";
}

std::string_view to_string(RotationState state) {
  switch (state) {
    case RotationState::unknown:
      return "UNKNOWN";
    case RotationState::moving:
      return "MOVING";
    case RotationState::arrived:
      return "ARRIVED";
    case RotationState::blocked:
      return "BLOCKED";
  }
  return "UNKNOWN";
}

std::optional<EventValue> named_value(const HandEvent& event) {
  const auto named = [&event](std::string_view name) { return EventValue{name, event.value}; };
  switch (event.kind) {
    case EventKind::grasped:
      return named("closing_force");
    case EventKind::arrived:
    case EventKind::missed:
    case EventKind::dropped:
      return named("grip_status");
    case EventKind::rotation_arrived:
    case EventKind::rotation_blocked:
      return named("rotation_status");
    case EventKind::online:
      return named("firmware_version");
    case EventKind::offline:
      return named("unanswered_requests");
    case EventKind::initialized:
    case EventKind::init_failed:
    case EventKind::fault:
    case EventKind::taken_over:
      break;
  }
  return std::nullopt;
}

std::string_view to_string(EventKind kind) {
  switch (kind) {
    case EventKind::online:
      return "ONLINE";
    case EventKind::offline:
      return "OFFLINE";
    case EventKind::initialized:
      return "INITIALIZED";
    case EventKind::init_failed:
      return "INIT_FAILED";
    case EventKind::arrived:
      return "ARRIVED";
    case EventKind::grasped:
      return "GRASPED";
    case EventKind::missed:
      return "MISSED";
    case EventKind::dropped:
      return "DROPPED";
    case EventKind::rotation_arrived:
      return "ROTATION_ARRIVED";
    case EventKind::rotation_blocked:
      return "ROTATION_BLOCKED";
    case EventKind::fault:
      return "FAULT";
    case EventKind::taken_over:
      return "TAKEN_OVER";
  }
  return "FAULT";
}

std::string HandAddress::to_string() const {
  return service + "/" + bus + "/" + std::to_string(can_id);
}

}  // namespace dh3
