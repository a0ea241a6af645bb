#pragma once
// Loop thread only: the bus loop asks and tells it; nothing else reaches it.
// Pure: it is told the time of each request it allows; it reads no clock.
//
// The share of a CAN line the scheduler offers at most
// (SchedulerOptions::max_line_load). On a CAN line, arbitration lets the
// lowest ID win, so a line asked for more than it carries starves the highest
// IDs; spacing requests so that each with its reply fits the share keeps it
// fair. After an idle moment the budget lets a few requests catch up
// (kLineBurst), no more.

#include <cstdint>

#include "dh3/base/clock.hpp"

namespace dh3::hand {

class LineBudget {
 public:
  /// An 8-byte CAN 2.0A frame with worst-case bit stuffing.
  static constexpr double kWorstCaseBitsPerFrame = 135.0;
  /// Requests the budget lets catch up after an idle moment.
  static constexpr int kLineBurst = 4;

  /// No limit when the line's bit rate is unknown (0) or `max_line_load` is 0.
  LineBudget(std::uint32_t bit_rate, double max_line_load);

  /// Whether a request may go at `now`.
  [[nodiscard]] bool allows(TimePoint now) const {
    return spacing_ == Duration::zero() || next_at_ <= now;
  }
  /// A request went at `now` (a group frame may go past the budget; it is
  /// still counted, so the requests after it wait their share).
  void used(TimePoint now);
  /// The earliest time a request may go (meaningful while limited).
  [[nodiscard]] TimePoint next_at() const { return next_at_; }
  /// The time a request and its reply take of the line at the allowed load;
  /// zero when unlimited.
  [[nodiscard]] Duration spacing() const { return spacing_; }

 private:
  Duration spacing_{};
  TimePoint next_at_{};
};

}  // namespace dh3::hand
