#include "lapse_judge.hpp"

#include "dh3/contract/ownership.hpp"

namespace dh3::detail {

void LapseJudge::take(TimePoint at, ReceiveState found) {
  last_look_ = at;
  switch (found) {
    case ReceiveState::unknown:
      blind_ = true;
      break;
    case ReceiveState::behind:
      was_behind_ = true;
      current_since_.reset();
      break;
    case ReceiveState::current:
      if (!current_since_) current_since_ = at;
      break;
  }
}

LapseJudge::TimePoint LapseJudge::next_look() const {
  if (blind_) return TimePoint::max();
  // The first look at once: a process already behind when Fast DDS reported
  // the lapse is caught by it.
  if (!last_look_) return reported_;
  const TimePoint believed = reported_ + contract::kOwnerLapseConfirm;
  if (!was_behind_ && *last_look_ < believed) return believed;
  return *last_look_ + kLookAgain;
}

bool LapseJudge::calls_end(TimePoint now) const {
  if (blind_) return now >= blind_end();
  if (!current_since_ || *last_look_ < reported_ + contract::kOwnerLapseConfirm) return false;
  return !was_behind_ || *last_look_ - *current_since_ >= kCaughtUpSpan;
}

LapseJudge::TimePoint LapseJudge::blind_end() const {
  return blind_ ? reported_ + contract::kOwnerLapseCallConfirm : TimePoint::max();
}

}  // namespace dh3::detail
