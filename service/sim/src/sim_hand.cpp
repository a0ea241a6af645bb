#include "dh3/sim/sim_hand.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "dh3/protocol/registers.hpp"

namespace dh3::sim {

namespace {

using protocol::Access;
using protocol::GripStatus;
using protocol::Message;

// Positions are doubles that move by speed * elapsed time; an axis counts as
// arrived when less than this is left, so rounding never keeps it "moving".
constexpr double kArrivalTolerance = 1e-9;

constexpr double kFullyOpen = 100.0;
constexpr double kRotationHome = 0.0;

std::int32_t whole_percent(double value) {
  return static_cast<std::int32_t>(std::lround(value));
}

double seconds_between(TimePoint from, TimePoint to) {
  return std::chrono::duration<double>(to - from).count();
}

}  // namespace

SimHand::SimHand(SimHandOptions options, TimePoint now)
    : options_(std::move(options)),
      object_(options_.object_position),
      obstacle_(options_.rotation_obstacle),
      closing_force_(options_.closing_force),
      opening_force_(options_.opening_force),
      can_id_(options_.id),
      stored_can_id_(options_.id),
      baud_index_(options_.baud_index),
      last_update_(now) {
  fingers_.position = kFullyOpen;
  fingers_.target = static_cast<std::int32_t>(kFullyOpen);
  fingers_.speed = options_.position_speed;
  rotation_.position = kRotationHome;
  rotation_.target = static_cast<std::int32_t>(kRotationHome);
  rotation_.speed = options_.rotation_speed;
}

std::vector<Outgoing> SimHand::handle(const Message& request, TimePoint now) {
  update(now);
  if (request.hand_id != can_id_ && request.hand_id != 0) return {};
  ++requests_seen_;
  if (muted_) return {};
  // ID 0 means "whichever hand is there", for the CAN ID register only.
  if (request.hand_id == 0 && request.reg != protocol::reg::kCanId) return {};

  const std::optional<Answer> reply_data = answer(request, now);
  if (!reply_data) return {};
  const Message reply{request.hand_id, request.reg, request.access, 0, reply_data->data};
  Duration delay = options_.reply_delay;
  if (reply_data->stored_setting) delay += options_.store_delay;
  return {Outgoing{now + delay, maybe_corrupt(reply)}};
}

std::vector<Outgoing> SimHand::advance(TimePoint now) {
  update(now);
  return std::exchange(unsolicited_, {});
}

std::optional<TimePoint> SimHand::next_unsolicited_at() const {
  if (!unsolicited_.empty()) return unsolicited_.front().due;
  if (init_feedback_ && init_done_at_) return init_done_at_;
  return std::nullopt;
}

void SimHand::reboot(TimePoint now) {
  update(now);
  can_id_ = stored_can_id_;
  initialized_ = false;
  init_done_at_.reset();
  init_feedback_ = false;
  closing_force_ = options_.closing_force;
  opening_force_ = options_.opening_force;
  for (Axis* axis : {&fingers_, &rotation_}) {
    axis->target = whole_percent(axis->position);
    axis->moving = false;
    axis->status = GripStatus::moving;
  }
  unsolicited_.clear();
  note_grip_change(now);
}

void SimHand::set_muted(bool muted) {
  muted_ = muted;
}

void SimHand::set_reply_delay(Duration delay) {
  options_.reply_delay = delay;
}

void SimHand::corrupt_next_replies(int count) {
  corrupt_remaining_ = count > 0 ? count : 0;
}

void SimHand::place_object(std::optional<std::int32_t> position) {
  object_ = position;
  // Fingers resting on the old object re-evaluate where they stop now.
  if (fingers_.status == GripStatus::caught && !fingers_.moving) {
    fingers_.moving = true;
    fingers_.status = GripStatus::moving;
    step_fingers(0.0);
  }
  note_grip_change(last_update_);
}

void SimHand::drop_object() {
  place_object(std::nullopt);
}

void SimHand::place_rotation_obstacle(std::optional<std::int32_t> position) {
  obstacle_ = position;
  rotation_obstacle_side_ = 0;
  if (rotation_.status == GripStatus::caught && !rotation_.moving) {
    rotation_.moving = true;
    rotation_.status = GripStatus::moving;
    step_rotation(0.0);
  }
}

std::uint8_t SimHand::id() const {
  return can_id_;
}
std::uint8_t SimHand::stored_id() const {
  return stored_can_id_;
}
std::int32_t SimHand::baud_index() const {
  return baud_index_;
}
bool SimHand::initialized() const {
  return initialized_;
}
bool SimHand::init_feedback_enabled() const {
  return init_feedback_;
}
bool SimHand::muted() const {
  return muted_;
}
double SimHand::position() const {
  return fingers_.position;
}
double SimHand::rotation() const {
  return rotation_.position;
}
GripStatus SimHand::grip_status() const {
  return fingers_.status;
}
GripStatus SimHand::rotation_status() const {
  return rotation_.status;
}
std::int32_t SimHand::closing_force() const {
  return closing_force_;
}
std::int32_t SimHand::opening_force() const {
  return opening_force_;
}
std::optional<std::int32_t> SimHand::object_position() const {
  return object_;
}
std::uint64_t SimHand::requests_seen() const {
  return requests_seen_;
}

void SimHand::update(TimePoint now) {
  // Nothing moves while initializing (commands are ignored), so finishing it
  // first and then moving for the whole interval is exact.
  if (init_done_at_ && now >= *init_done_at_) {
    const TimePoint done_at = *init_done_at_;
    finish_initialization();
    if (init_feedback_ && !muted_) {
      // The document's unsolicited frame: 08 02, read flag, data 0.
      const Message finished{can_id_, protocol::reg::kInitialize, Access::read, 0, 0};
      unsolicited_.push_back(Outgoing{done_at, maybe_corrupt(finished)});
    }
  }
  if (now <= last_update_) return;  // time never runs backwards for the model
  const double seconds = seconds_between(last_update_, now);
  const bool fingers_were_moving = fingers_.moving;
  step_fingers(seconds);
  step_rotation(seconds);
  const TimePoint stopped_at =
      fingers_were_moving && !fingers_.moving
          ? last_update_ + std::chrono::duration_cast<Duration>(
                               std::chrono::duration<double>(fingers_.stopped_after))
          : now;
  last_update_ = now;
  note_grip_change(std::min(stopped_at, now));
}

void SimHand::note_grip_change(TimePoint at) {
  if (fingers_.status == noted_grip_) return;
  noted_grip_ = fingers_.status;
  grip_since_ = at;
}

TimePoint SimHand::grip_status_since() const {
  return grip_since_;
}

void SimHand::finish_initialization() {
  init_done_at_.reset();
  initialized_ = true;
  // Calibration ends with the fingers fully open and the rotation at home.
  fingers_ = Axis{kFullyOpen, static_cast<std::int32_t>(kFullyOpen), options_.position_speed, false,
                  GripStatus::moving};
  rotation_ = Axis{kRotationHome, static_cast<std::int32_t>(kRotationHome), options_.rotation_speed,
                   false, GripStatus::moving};
}

void SimHand::step_fingers(double seconds) {
  if (fingers_.moving) step_axis(fingers_, seconds, finger_stop());
}

void SimHand::step_rotation(double seconds) {
  if (!rotation_.moving) return;
  if (obstacle_) {
    // Remember on which side of the obstacle the rotation is, so that leaving
    // it after being blocked works and pushing through it does not.
    if (rotation_.position < *obstacle_) rotation_obstacle_side_ = -1;
    if (rotation_.position > *obstacle_) rotation_obstacle_side_ = 1;
  }
  step_axis(rotation_, seconds, rotation_stop());
}

void SimHand::step_axis(Axis& axis, double seconds, std::optional<double> stop) {
  const double end = stop.value_or(static_cast<double>(axis.target));
  const double remaining = std::abs(end - axis.position);
  const double travel = axis.speed * seconds;
  if (travel + kArrivalTolerance >= remaining) {
    axis.stopped_after = axis.speed > 0.0 ? std::min(seconds, remaining / axis.speed) : 0.0;
    axis.position = end;
    axis.moving = false;
    axis.status = stop ? GripStatus::caught : GripStatus::arrived;
    return;
  }
  axis.position += end > axis.position ? travel : -travel;
}

std::optional<double> SimHand::finger_stop() const {
  // Only closing catches: the object sits between the fingers, below them.
  if (object_ && fingers_.target < *object_ && fingers_.position >= *object_) {
    return static_cast<double>(*object_);
  }
  return std::nullopt;
}

std::optional<double> SimHand::rotation_stop() const {
  if (!obstacle_) return std::nullopt;
  const double obstacle = *obstacle_;
  const double position = rotation_.position;
  const bool below = position < obstacle || (position == obstacle && rotation_obstacle_side_ < 0);
  const bool above = position > obstacle || (position == obstacle && rotation_obstacle_side_ > 0);
  if (rotation_.target > obstacle && below) return obstacle;
  if (rotation_.target < obstacle && above) return obstacle;
  return std::nullopt;
}

void SimHand::start_motion(Axis& axis, std::int32_t target) {
  axis.target = target;
  axis.moving = true;
  axis.status = GripStatus::moving;
  // Already there (or already against the object): settle at once.
  step_fingers(0.0);
  step_rotation(0.0);
  note_grip_change(last_update_);
}

std::optional<SimHand::Answer> SimHand::answer(const Message& request, TimePoint now) {
  namespace reg = protocol::reg;
  const protocol::Register r = request.reg;
  const bool write = request.access == Access::write;
  // A write the document allows with a value in its range; anything else is
  // answered with the value the register keeps (see the header).
  const bool apply = write && protocol::check_write(r, request.data).ok();

  if (r == reg::kInitFeedback) {
    if (write) init_feedback_ = true;
    return Answer{init_feedback_ ? protocol::kInitFeedbackEnabled : 0};
  }
  if (r == reg::kInitialize) {
    if (!write) return Answer{initialized_ ? 1 : 0};
    // A new initialization interrupts the running one and any motion.
    initialized_ = false;
    init_done_at_ = now + options_.init_time;
    for (Axis* axis : {&fingers_, &rotation_}) {
      axis->moving = false;
      axis->status = GripStatus::moving;
    }
    return Answer{request.data};
  }
  if (r == reg::kClosingForce || r == reg::kOpeningForce) {
    std::int32_t& force = r == reg::kClosingForce ? closing_force_ : opening_force_;
    if (apply) force = request.data;
    return Answer{force};
  }
  if (r == reg::kPosition || r == reg::kRotation) {
    Axis& axis = r == reg::kPosition ? fingers_ : rotation_;
    if (!apply) return Answer{whole_percent(axis.position)};
    if (initialized_) start_motion(axis, request.data);
    return Answer{request.data};
  }
  if (r == reg::kGripStatus) return Answer{static_cast<std::int32_t>(fingers_.status)};
  if (r == reg::kRotationStatus) return Answer{static_cast<std::int32_t>(rotation_.status)};
  if (r == reg::kCanId) {
    if (apply) stored_can_id_ = static_cast<std::uint8_t>(request.data);
    return Answer{apply ? request.data : stored_can_id_, apply};
  }
  if (r == reg::kFirmwareVersion) return Answer{options_.firmware_version};
  if (r == reg::kBaudRate) {
    if (apply) baud_index_ = request.data;
    return Answer{baud_index_, apply};
  }
  return std::nullopt;
}

Message SimHand::maybe_corrupt(Message message) {
  if (corrupt_remaining_ <= 0) return message;
  --corrupt_remaining_;
  message.data ^= 0xFF;
  return message;
}

}  // namespace dh3::sim
