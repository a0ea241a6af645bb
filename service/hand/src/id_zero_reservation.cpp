#include "id_zero_reservation.hpp"

#include <algorithm>

namespace dh3::hand {

std::optional<TimePoint> IdZeroReservation::reserve(bool waiting, TimePoint earliest) {
  if (!waiting) {
    slot_.reset();
    return std::nullopt;
  }
  if (slot_) return std::nullopt;
  slot_ = std::max(earliest, others_clear_at());
  return slot_;
}

bool IdZeroReservation::may_send(TimePoint now) {
  if (now >= others_clear_at()) return true;
  slot_.reset();
  return false;
}

void IdZeroReservation::frame_sent(std::uint8_t can_id, TimePoint left) {
  if (can_id != 0) {
    others_last_ = std::max(others_last_, left);
    return;
  }
  id_zero_last_ = left;
  slot_.reset();
}

void IdZeroReservation::probe_sent(TimePoint left) {
  others_last_ = std::max(others_last_, left);
}

TimePoint IdZeroReservation::probes_allowed_at() const {
  TimePoint allowed{};
  if (id_zero_last_) allowed = *id_zero_last_ + spacing_;
  if (slot_) allowed = std::max(allowed, *slot_ + spacing_);
  return allowed;
}

}  // namespace dh3::hand
