#include "dh3/sim/interval_watch.hpp"

#include <spdlog/spdlog.h>

#include "dh3/protocol/registers.hpp"

namespace dh3::sim {

bool IntervalWatch::note(std::uint8_t hand_id, Duration at, const protocol::Message& frame) {
  if (!enabled() || !protocol::is_known(frame.reg) || frame.reserve != 0) return false;
  std::optional<Duration>& last = last_[hand_id];
  const std::optional<Duration> previous = last;
  last = at;
  if (!previous || at < *previous) return false;
  const Duration gap = at - *previous;
  if (gap >= minimum_) return false;
  ++violations_;
  using Milliseconds = std::chrono::duration<double, std::milli>;
  spdlog::warn(
      "dh3-sim: interval violation: hand {}: [{}] came {:.3f} ms after the previous "
      "frame to it (minimum {:.0f} ms; {} so far)",
      hand_id, protocol::describe(frame), Milliseconds(gap).count(), Milliseconds(minimum_).count(),
      violations_);
  return true;
}

}  // namespace dh3::sim
