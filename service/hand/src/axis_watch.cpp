#include "axis_watch.hpp"

namespace dh3::hand {

template <class Motion>
void AxisWatch<Motion>::start(const Motion& motion) {
  motion_ = motion;
  value_read_ = false;
}

template <class Motion>
bool AxisWatch<Motion>::take_status(bool moving, bool stale, bool arrival) {
  // A 0 during the motion: the hand took the command, so a 2 after it is
  // this motion's arrival, wherever the value was last read.
  if (motion_ && moving) motion_->moving_seen = true;
  if (!stale) return true;
  if (arrival && !recheck_arrival_) {
    recheck_arrival_ = true;
    read_due_ = true;
  }
  return false;
}

template <class Motion>
void AxisWatch<Motion>::end(bool at_target) {
  motion_.reset();
  read_due_ = !at_target;
}

template <class Motion>
bool AxisWatch<Motion>::take_read_due() {
  const bool due = read_due_;
  read_due_ = false;
  return due;
}

template <class Motion>
void AxisWatch<Motion>::read_answered() {
  // That read is where the axis stopped, whatever the rechecked arrival said.
  read_due_ = false;
  recheck_arrival_ = false;
}

template <class Motion>
void AxisWatch<Motion>::clear() {
  motion_.reset();
  read_due_ = false;
  recheck_arrival_ = false;
}

template class AxisWatch<FingerMotion>;
template class AxisWatch<RotationMotion>;

}  // namespace dh3::hand
