#include "dh3/hand/observed_hands.hpp"

#include <algorithm>

#include "hand_driver_states.hpp"
#include "status_reading.hpp"

namespace dh3::hand {
namespace reg = protocol::reg;

namespace {
struct Pending {
  protocol::Register reg;
  TimePoint at;
};
}  // namespace

struct ObservedHands::Hand {
  bool known = false;
  HandState state;
  /// Requests waiting for their replies, one per register at most: the
  /// active service's frame in flight, and an unsolicited 0x0802 beside it.
  std::vector<Pending> pending;
  std::deque<ObservedWrite> writes;
  std::optional<FingerMotion> finger;
  std::optional<RotationMotion> rotation;
  bool hold_untouched = false;
};

ObservedHands::~ObservedHands() = default;

ObservedHands::ObservedHands(const std::vector<HandConfig>& configured, Duration reply_window)
    : reply_window_(reply_window), hands_(std::make_unique<std::array<Hand, 256>>()) {
  for (const HandConfig& config : configured) {
    if (config.can_id == 0) continue;
    Hand& hand = (*hands_)[config.can_id];
    hand.known = true;
    hand.state.can_id = config.can_id;
    hand.state.name = config.name;
  }
}

FrameRole ObservedHands::on_frame(const bus::CanFrame& frame, TimePoint now) {
  if (frame.id > 0xFF || frame.length != protocol::kPayloadSize) return FrameRole::undecodable;
  const auto id = static_cast<std::uint8_t>(frame.id);
  const auto message = protocol::decode_payload(id, std::span(frame.data.data(), frame.length));
  if (!message) return FrameRole::undecodable;
  Hand& hand = (*hands_)[id];
  std::erase_if(hand.pending, [&](const Pending& p) { return now - p.at > reply_window_; });
  const auto pending = std::find_if(hand.pending.begin(), hand.pending.end(),
                                    [&](const Pending& p) { return p.reg == message->reg; });
  const bool answers_pending = pending != hand.pending.end();
  const bool carries_a_reading =
      message->access == protocol::Access::read && (message->data != 0 || message->reserve != 0);
  if (!answers_pending && !carries_a_reading) {
    on_request(hand, *message, now);
    return FrameRole::request;
  }
  if (answers_pending) hand.pending.erase(pending);
  on_reply(hand, *message, answers_pending, now);
  return FrameRole::reply;
}

void ObservedHands::on_request(Hand& hand, const protocol::Message& request, TimePoint now) {
  ++requests_seen_;
  hand.pending.push_back(Pending{request.reg, now});
  if (request.access != protocol::Access::write) return;
  hand.writes.push_back(ObservedWrite{request, now, false});
  if (hand.writes.size() > kWritesKept) hand.writes.pop_front();
}

void ObservedHands::on_reply(Hand& hand, const protocol::Message& reply, bool answered,
                             TimePoint now) {
  if (reply.hand_id == 0) return;  // whichever hand is there: not one we can name
  if (!hand.known) {
    hand.known = true;
    hand.state.can_id = reply.hand_id;
  }
  hand.state.online = true;
  hand.state.read_at = now;
  if (reply.access == protocol::Access::write) {
    if (answered) on_echo(hand, reply);
  } else {
    on_read(hand, reply);
  }
  ++hand.state.sequence;
  hand.state.updated_at = now;
}

void ObservedHands::on_echo(Hand& hand, const protocol::Message& echo) {
  for (auto it = hand.writes.rbegin(); it != hand.writes.rend(); ++it) {
    if (it->request == echo) {
      it->echoed = true;
      break;
    }
  }
  HandState& state = hand.state;
  if (echo.reg == reg::kInitialize) {
    state.initialized = false;  // initializing until 0x0802 reads 1
  } else if (echo.reg == reg::kClosingForce) {
    state.closing_force = echo.data;
  } else if (echo.reg == reg::kOpeningForce) {
    state.opening_force = echo.data;
  } else if (echo.reg == reg::kPosition) {
    hand.finger = FingerMotion{echo.data, echo.data == 0,
                               state.position < 0 || echo.data < state.position};
    hand.hold_untouched = false;
    state.target_position = echo.data;
    state.grip = GripState::moving;
  } else if (echo.reg == reg::kRotation) {
    hand.rotation = RotationMotion{echo.data};
    state.rotation_target = echo.data;
    state.rotation_state = RotationState::moving;
  }
}

void ObservedHands::on_read(Hand& hand, const protocol::Message& reply) {
  HandState& state = hand.state;
  if (reply.reg == reg::kInitialize) {
    state.initialized = reply.data == 1;
  } else if (reply.reg == reg::kClosingForce) {
    state.closing_force = reply.data;
  } else if (reply.reg == reg::kOpeningForce) {
    state.opening_force = reply.data;
  } else if (reply.reg == reg::kPosition) {
    state.position = reply.data;
  } else if (reply.reg == reg::kRotation) {
    state.rotation = reply.data;
  } else if (reply.reg == reg::kGripStatus) {
    on_grip_status(hand, protocol::status_value(reply));
  } else if (reply.reg == reg::kRotationStatus) {
    on_rotation_status(hand, protocol::status_value(reply));
  } else if (reply.reg == reg::kFirmwareVersion) {
    state.firmware_version = reply.data;
  }
}

void ObservedHands::on_grip_status(Hand& hand, std::int32_t status) {
  const GripReading reading = read_grip_status(
      status, FingerView{hand.state.grip, hand.finger, hand.hold_untouched, hand.state.position, 0});
  if (hand.finger && status == static_cast<std::int32_t>(FingerStatus::moving)) {
    hand.finger->moving_seen = true;
  }
  if (reading.stale) return;  // the active service reads again; its reply is seen
  if (reading.hold_starts) hand.hold_untouched = true;
  if (reading.motion_ended) hand.finger.reset();
  if (reading.grip) hand.state.grip = *reading.grip;
}

void ObservedHands::on_rotation_status(Hand& hand, std::int32_t status) {
  const RotationReading reading =
      read_rotation_status(status, RotationView{hand.rotation, hand.state.rotation, 0});
  if (hand.rotation && status == static_cast<std::int32_t>(RotationStatus::moving)) {
    hand.rotation->moving_seen = true;
  }
  if (reading.stale) return;
  if (reading.motion_ended) hand.rotation.reset();
  if (reading.state) hand.state.rotation_state = *reading.state;
}

std::vector<HandState> ObservedHands::states() const {
  std::vector<HandState> out;
  for (const Hand& hand : *hands_) {
    if (hand.known) out.push_back(hand.state);
  }
  return out;
}

std::optional<HandState> ObservedHands::state(std::uint8_t can_id) const {
  const Hand& hand = (*hands_)[can_id];
  if (!hand.known) return std::nullopt;
  return hand.state;
}

const std::deque<ObservedWrite>& ObservedHands::writes(std::uint8_t can_id) const {
  return (*hands_)[can_id].writes;
}

std::optional<std::int32_t> ObservedHands::finger_motion(std::uint8_t can_id) const {
  const auto& motion = (*hands_)[can_id].finger;
  return motion ? std::optional(motion->target) : std::nullopt;
}

std::optional<std::int32_t> ObservedHands::rotation_motion(std::uint8_t can_id) const {
  const auto& motion = (*hands_)[can_id].rotation;
  return motion ? std::optional(motion->target) : std::nullopt;
}

}  // namespace dh3::hand
