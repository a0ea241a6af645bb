// ExpiryTimer: sweeps when woken and when its deadline passes, never after stop().

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <optional>

#include "expiry_timer.hpp"

namespace dh3::dds {
namespace {

using namespace std::chrono_literals;

/// Counts sweeps; a test waits for a count (bounded, so a broken timer fails
/// the test instead of hanging it; no duration is asserted).
class Sweeps {
 public:
  void add() {
    {
      std::lock_guard lock(mutex_);
      ++count_;
    }
    cv_.notify_all();
  }
  bool reach(int count) {
    std::unique_lock lock(mutex_);
    return cv_.wait_for(lock, 30s, [&] { return count_ >= count; });
  }
  int count() {
    std::lock_guard lock(mutex_);
    return count_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  int count_ = 0;
};

TEST(ExpiryTimerTest, WakeRunsASweepWithoutADeadline) {
  Sweeps looks;  // the timer looked for its next deadline, then waits
  Sweeps sweeps;
  ExpiryTimer timer(
      [&]() -> std::optional<TimePoint> {
        looks.add();
        return std::nullopt;
      },
      [&] { sweeps.add(); });
  timer.start();
  // A wake-up before the timer's first look is news it has already seen.
  ASSERT_TRUE(looks.reach(1));
  timer.wake();
  EXPECT_TRUE(sweeps.reach(1));
  // After each sweep it looks again.
  ASSERT_TRUE(looks.reach(2));
  timer.wake();
  EXPECT_TRUE(sweeps.reach(2));
  timer.stop();
}

TEST(ExpiryTimerTest, PassedDeadlineRunsASweepUnwoken) {
  Sweeps sweeps;
  std::atomic<bool> due{true};
  ExpiryTimer timer(
      [&]() -> std::optional<TimePoint> {
        // Due at once the first time; then nothing is left.
        if (due.exchange(false)) return SteadyClock::now() - 1s;
        return std::nullopt;
      },
      [&] { sweeps.add(); });
  timer.start();
  EXPECT_TRUE(sweeps.reach(1));
  timer.stop();
  EXPECT_EQ(sweeps.count(), 1);
}

TEST(ExpiryTimerTest, NoSweepAfterStop) {
  Sweeps sweeps;
  ExpiryTimer timer([]() -> std::optional<TimePoint> { return std::nullopt; },
                    [&] { sweeps.add(); });
  timer.start();
  timer.stop();
  timer.wake();
  timer.stop();  // idempotent
  EXPECT_EQ(sweeps.count(), 0);
}

TEST(ExpiryTimerTest, StopWithoutStartReturns) {
  int sweeps = 0;
  ExpiryTimer timer([]() -> std::optional<TimePoint> { return std::nullopt; }, [&] { ++sweeps; });
  timer.wake();
  timer.stop();
  EXPECT_EQ(sweeps, 0);
}

}  // namespace
}  // namespace dh3::dds
