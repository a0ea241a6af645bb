#include "conversions.hpp"

#include <chrono>
#include <cstdio>

#include "dh3/contract/value_ranges.hpp"

namespace dh3::detail {

Code to_code(msg::ResultCode code) {
  switch (code) {
    case msg::OK:
      return Code::ok;
    case msg::INVALID_ARGUMENT:
      return Code::invalid_argument;
    case msg::UNKNOWN_HAND:
      return Code::unknown_hand;
    case msg::TIMEOUT:
      return Code::timeout;
    case msg::BUS_DOWN:
      return Code::bus_down;
    case msg::BUSY:
      return Code::busy;
    case msg::NOT_INITIALIZED:
      return Code::not_initialized;
    case msg::DENIED:
      return Code::denied;
    case msg::CANCELLED:
      return Code::cancelled;
    case msg::FAILED:
      return Code::failed;
  }
  // A value this client does not know (a newer service): not a success.
  return Code::failed;
}

GraspOutcome to_public(msg::GraspOutcome outcome) {
  switch (outcome) {
    case msg::GRASPED:
      return GraspOutcome::grasped;
    case msg::MISSED:
      return GraspOutcome::missed;
    case msg::GRASP_NONE:
      break;
  }
  return GraspOutcome::none;
}

GripState to_public(msg::GripState state) {
  switch (state) {
    case msg::GRIP_MOVING:
      return GripState::moving;
    case msg::GRIP_ARRIVED:
      return GripState::arrived;
    case msg::GRIP_GRASPED:
      return GripState::grasped;
    case msg::GRIP_MISSED:
      return GripState::missed;
    case msg::GRIP_DROPPED:
      return GripState::dropped;
    case msg::GRIP_UNKNOWN:
      break;
  }
  return GripState::unknown;
}

RotationState to_public(msg::RotationState state) {
  switch (state) {
    case msg::ROTATION_MOVING:
      return RotationState::moving;
    case msg::ROTATION_ARRIVED:
      return RotationState::arrived;
    case msg::ROTATION_BLOCKED:
      return RotationState::blocked;
    case msg::ROTATION_UNKNOWN:
      break;
  }
  return RotationState::unknown;
}

EventKind to_public(msg::EventKind kind) {
  switch (kind) {
    case msg::EVENT_ONLINE:
      return EventKind::online;
    case msg::EVENT_OFFLINE:
      return EventKind::offline;
    case msg::EVENT_INITIALIZED:
      return EventKind::initialized;
    case msg::EVENT_INIT_FAILED:
      return EventKind::init_failed;
    case msg::EVENT_ARRIVED:
      return EventKind::arrived;
    case msg::EVENT_GRASPED:
      return EventKind::grasped;
    case msg::EVENT_MISSED:
      return EventKind::missed;
    case msg::EVENT_DROPPED:
      return EventKind::dropped;
    case msg::EVENT_ROTATION_ARRIVED:
      return EventKind::rotation_arrived;
    case msg::EVENT_ROTATION_BLOCKED:
      return EventKind::rotation_blocked;
    case msg::EVENT_FAULT:
      break;
  }
  return EventKind::fault;
}

HandAddress to_public(const msg::HandAddress& address) {
  return HandAddress{address.service(), address.bus(), address.can_id()};
}

msg::HandAddress to_msg(const HandAddress& address) {
  msg::HandAddress out;
  out.service(address.service);
  out.bus(address.bus);
  out.can_id(address.can_id);
  return out;
}

HandStatus to_public(const msg::HandStatus& s) {
  HandStatus out;
  out.address = HandAddress{s.service(), s.bus(), s.can_id()};
  out.name = s.name();
  out.online = s.online();
  out.initialized = s.initialized();
  out.grip = to_public(s.grip());
  out.position = s.position();
  out.target_position = s.target_position();
  out.closing_force = s.closing_force();
  out.opening_force = s.opening_force();
  out.rotation = s.rotation();
  out.rotation_target = s.rotation_target();
  out.rotation_state = to_public(s.rotation_state());
  out.firmware_version = s.firmware_version();
  out.firmware_version_text = s.firmware_version_text();
  out.last_error = to_code(s.last_error());
  out.last_error_message = s.last_error_message();
  out.lease_holder = s.lease_holder();
  out.timestamp_ns = s.timestamp_ns();
  out.update_seq = s.update_seq();
  out.read_at_ns = s.read_at_ns();
  return out;
}

HandEvent to_public(const msg::HandEvent& e) {
  HandEvent out;
  out.hand = to_public(e.hand());
  out.name = e.name();
  out.kind = to_public(e.kind());
  if (e.position_known()) out.position = e.position();
  out.target = e.target();
  out.value = e.value();
  out.message = e.message();
  out.timestamp_ns = e.timestamp_ns();
  out.event_seq = e.event_seq();
  return out;
}

ServiceInfo to_public(const msg::ServiceInfo& info) {
  ServiceInfo out;
  out.name = info.service();
  out.version = info.version();
  out.host = info.host();
  out.admin_allowed = info.admin_allowed();
  out.started_ns = info.started_ns();
  for (const auto& bus : info.buses()) {
    BusInfo b;
    b.name = bus.name();
    b.spec = bus.spec();
    b.link_up = bus.link_up();
    for (const auto& hand : bus.hands()) b.hands.push_back(HandInfo{hand.can_id(), hand.name()});
    out.buses.push_back(std::move(b));
  }
  return out;
}

Reply to_reply(const msg::CommandReply& reply) {
  Reply out;
  out.code = to_code(reply.code());
  out.message = reply.message();
  if (out.code != Code::ok && out.message.empty()) {
    out.message =
        command_name(reply.command()) + " failed with " + std::string(to_string(out.code));
  }
  out.value = reply.value();
  out.grasp = to_public(reply.grasp());
  out.found_ids = reply.found_ids();
  out.lease_holder = reply.lease_holder();
  return out;
}

namespace {

Failure<Reply> invalid(std::string message) {
  Reply reply;
  reply.code = Code::invalid_argument;
  reply.message = std::move(message);
  return fail(std::move(reply));
}

}  // namespace

Result<void, Reply> check_request(const msg::CommandRequest& request) {
  const auto& hand = request.hand();
  if (hand.service().empty()) return invalid("the hand's service name is empty");
  if (hand.bus().empty()) return invalid("the hand's bus name is empty");
  if (hand.service().size() > limits::MAX_NAME_LENGTH ||
      hand.bus().size() > limits::MAX_NAME_LENGTH) {
    return invalid("service and bus names are at most " + std::to_string(limits::MAX_NAME_LENGTH) +
                   " characters");
  }
  const std::string name = command_name(request.command());
  if (request.command() != msg::SCAN &&
      (hand.can_id() < limits::CAN_ID_MIN || hand.can_id() > limits::CAN_ID_MAX)) {
    return invalid(name + " needs a hand's CAN ID (" + std::to_string(limits::CAN_ID_MIN) + "-" +
                   std::to_string(limits::CAN_ID_MAX) + "), not " + std::to_string(hand.can_id()));
  }
  if (auto in_range = contract::check_value_range(request); !in_range) {
    return invalid(std::move(in_range).error());
  }
  return {};
}

std::string describe_duration(std::chrono::milliseconds duration) {
  const auto ms = duration.count();
  if (ms < 1000) return std::to_string(ms) + " ms";
  char text[32];
  std::snprintf(text, sizeof text, "%.3g s", static_cast<double>(ms) / 1000.0);
  return text;
}

}  // namespace dh3::detail
