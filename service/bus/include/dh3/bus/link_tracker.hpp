#pragma once
// The up/down bookkeeping every reconnecting backend shares: the link's state,
// exponential backoff between attempts (measured on the injected Clock, so
// tests step through it with a FakeClock), and one log line per transition
// rather than one per failed retry.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>

#include "dh3/base/clock.hpp"
#include "dh3/bus/bus.hpp"

namespace dh3::bus {

struct ReconnectOptions {
  /// Wait before the first retry after a failed attempt or a drop.
  Duration initial_backoff = std::chrono::milliseconds(100);
  /// The wait doubles after each failed attempt, up to this.
  Duration max_backoff = std::chrono::seconds(5);
};

class LinkTracker {
 public:
  /// `name` prefixes every log line, e.g. "tcp:192.168.1.20:8888".
  LinkTracker(std::string name, ReconnectOptions options);

  /// An attempt (or the first open) succeeded. Logs if the link was down.
  void mark_up();
  /// An attempt failed or the live link dropped at `now`, for `reason`.
  /// Schedules the next attempt after the current backoff, then doubles it.
  void mark_down(std::string_view reason, TimePoint now);
  /// Counts an attempt (for diagnostics and tests).
  void count_attempt() { ++attempts_; }

  [[nodiscard]] LinkState state() const { return state_.load(std::memory_order_relaxed); }
  [[nodiscard]] bool retry_due(TimePoint now) const { return now >= next_attempt_at_; }
  [[nodiscard]] TimePoint next_attempt_at() const { return next_attempt_at_; }
  /// Open attempts so far, the first one included.
  [[nodiscard]] std::uint64_t attempts() const { return attempts_; }
  /// Times a link that was up went down.
  [[nodiscard]] std::uint64_t drops() const { return drops_; }

 private:
  std::string name_;
  ReconnectOptions options_;
  std::atomic<LinkState> state_{LinkState::down};
  bool ever_up_ = false;
  bool failure_logged_ = false;  // a warning for the current down period went out
  Duration next_delay_{};
  TimePoint next_attempt_at_{};  // epoch: the first attempt is due at once
  std::uint64_t attempts_ = 0;
  std::uint64_t drops_ = 0;
};

}  // namespace dh3::bus
