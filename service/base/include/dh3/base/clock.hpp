#pragma once
// Time as the service sees it. Everything that schedules (pacing, timeouts,
// polling, simulated motion) asks a Clock, so tests can drive time by hand
// instead of sleeping.

#include <atomic>
#include <chrono>

namespace dh3 {

using SteadyClock = std::chrono::steady_clock;
using TimePoint = SteadyClock::time_point;
using Duration = SteadyClock::duration;

class Clock {
 public:
  virtual ~Clock() = default;
  [[nodiscard]] virtual TimePoint now() const = 0;
};

/// The real monotonic clock.
class SystemClock final : public Clock {
 public:
  [[nodiscard]] TimePoint now() const override { return SteadyClock::now(); }
  static const SystemClock& instance() {
    static const SystemClock clock;
    return clock;
  }
};

/// A clock that moves only when told to. Safe to read from any thread.
class FakeClock final : public Clock {
 public:
  explicit FakeClock(TimePoint start = TimePoint{} + std::chrono::hours(1)) : now_(start) {}
  [[nodiscard]] TimePoint now() const override { return now_.load(); }
  void advance(Duration by) { now_.store(now_.load() + by); }
  void set(TimePoint to) { now_.store(to); }

 private:
  std::atomic<TimePoint> now_;
};

}  // namespace dh3
