#pragma once
// Loop thread only: the hand's driver asks and tells it; nothing else reaches it.
// Pure: it is told what was sent and read; it reads no clock and sends nothing.
//
// One axis of a hand (the fingers, the rotation) as its driver watches it: the
// motion commanded on it, the read that confirms where it stopped once its
// status ended it, and an arrival status that may be a reading from before the
// motion. A status 2 read before any 0 of the motion, while the value last read
// is far from the target, is the arrival of a short motion or a reading from
// before it: the confirming read is sent at once and the arrival is read again
// against it, instead of a poll some frames later. Both axes follow these
// rules; what a status value means on each is status_reading.hpp.

#include <cstdint>
#include <optional>

#include "hand_driver_states.hpp"

namespace dh3::hand {

/// `Motion`: FingerMotion or RotationMotion (a `target`, and `moving_seen`).
template <class Motion>
class AxisWatch {
 public:
  /// A motion's frame was sent: it runs until a status ends it.
  void start(const Motion& motion);
  /// The motion running, if any.
  [[nodiscard]] const std::optional<Motion>& motion() const { return motion_; }
  /// The axis's value (position, rotation) was read.
  void value_read() {
    if (motion_) value_read_ = true;
  }
  /// A read during the running motion found the axis at `value`, its target.
  [[nodiscard]] bool read_at_target(std::int32_t value) const {
    return motion_ && value_read_ && value == motion_->target;
  }

  /// A status value of this axis was read, and status_reading.hpp said what
  /// it means: `moving` (it is the "moving" value), `stale` (it may be from
  /// before the running motion), `arrival` (it is the "arrived" value). False
  /// if the reading is to be ignored: a stale one, or an arrival that the
  /// confirming read, now due, is to decide.
  [[nodiscard]] bool take_status(bool moving, bool stale, bool arrival);
  /// A status ended the motion (its event goes out now): where the axis
  /// stopped is read next, unless a read during the motion found it there.
  void end(bool at_target);

  /// The confirming read is to be sent (once: this takes it).
  [[nodiscard]] bool take_read_due();
  [[nodiscard]] bool read_due() const { return read_due_; }
  /// The confirming read is to decide an arrival that looked stale: the
  /// caller reads the arrival again once that read is answered.
  [[nodiscard]] bool rechecking() const { return recheck_arrival_; }
  /// The confirming read was answered (and a rechecked arrival read again).
  void read_answered();
  /// The confirming read went unanswered: the status is polled again anyway.
  void read_lost() { recheck_arrival_ = false; }

  /// Initialization restarted: no motion of ours runs any more.
  void forget_motion() { motion_.reset(); }
  /// The link ended: no motion, nothing to read.
  void clear();

  /// The last status value outside the document reported on this axis (0:
  /// none), so that a hand that keeps sending it is reported once.
  [[nodiscard]] std::int32_t last_undefined() const { return last_undefined_; }
  void undefined_reported(std::int32_t status) { last_undefined_ = status; }

 private:
  std::optional<Motion> motion_;
  bool value_read_ = false;       ///< since the running motion began
  bool read_due_ = false;         ///< the confirming read is still to be sent
  bool recheck_arrival_ = false;  ///< that read decides an arrival that looked stale
  std::int32_t last_undefined_ = 0;
};

extern template class AxisWatch<FingerMotion>;
extern template class AxisWatch<RotationMotion>;

}  // namespace dh3::hand
