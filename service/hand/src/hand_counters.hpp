#pragma once
// The counters behind hand_metrics.hpp. Internal to the hand layer: the
// scheduler owns them, its drivers count into them.

#include <array>
#include <atomic>
#include <cstdint>

#include "dh3/base/clock.hpp"
#include "dh3/hand/hand_metrics.hpp"
#include "dh3/hand/hand_types.hpp"
#include "dh3/hand/latency_histogram.hpp"

namespace dh3::hand {

/// One hand's counters. Counting is safe from any thread; snapshot() too.
class HandCounters {
 public:
  void count_command(const Command& command, const CommandResult& result);
  void count_timeout() { timeouts_.fetch_add(1, std::memory_order_relaxed); }
  void count_retry() { retries_.fetch_add(1, std::memory_order_relaxed); }
  void observe_round_trip(Duration round_trip);

  [[nodiscard]] std::uint64_t timeouts() const { return timeouts_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t retries() const { return retries_.load(std::memory_order_relaxed); }

  /// Fills the counted fields of `out` (not its identity or online state).
  void snapshot(HandMetrics& out) const;

  /// Command types as counted: every CommandKind, and write_register split by
  /// the registers the contract has a command for.
  static constexpr std::size_t kTypes = 13;
  /// OK and every CommandError.
  static constexpr std::size_t kResults = 9;

 private:
  std::array<std::atomic<std::uint64_t>, kTypes * kResults> commands_{};
  std::atomic<std::uint64_t> timeouts_{0};
  std::atomic<std::uint64_t> retries_{0};
  std::array<std::atomic<std::uint64_t>, kRoundTripBuckets.size() + 1> round_trip_{};
  std::atomic<std::uint64_t> round_trip_ns_{0};
};

/// The histograms behind BusLatency (hand_metrics.hpp), one set per bus: the
/// scheduler owns them, its drivers observe into them on the loop thread, a
/// scrape takes snapshot() on its own (LatencyHistogram's threading rule).
struct BusLatencyCounters {
  LatencyHistogram command_to_frame;
  LatencyHistogram frame_to_reply;
  LatencyHistogram command_to_reply;
  LatencyHistogram sample_age;
  [[nodiscard]] BusLatency snapshot() const {
    return {command_to_frame.snapshot(), frame_to_reply.snapshot(), command_to_reply.snapshot(),
            sample_age.snapshot()};
  }
};

/// Frames over a recent window, for the bus-load figure. count() and roll()
/// on the loop thread; frames_per_second() from any thread.
class RecentFrames {
 public:
  static constexpr Duration kSlot = std::chrono::seconds(1);
  static constexpr std::size_t kSlots = 5;  ///< the window: the last 5 whole seconds

  explicit RecentFrames(TimePoint now) : slot_start_(now) {}
  void count(std::uint64_t frames) { current_ += frames; }
  /// Closes the slots that ended by `now` and publishes the window's rate.
  void roll(TimePoint now);
  /// 0 until the first slot has ended.
  [[nodiscard]] double frames_per_second() const {
    return per_second_.load(std::memory_order_relaxed);
  }

 private:
  TimePoint slot_start_;
  std::uint64_t current_ = 0;
  std::array<std::uint64_t, kSlots> slots_{};
  std::size_t next_slot_ = 0;
  std::size_t filled_ = 0;
  std::atomic<double> per_second_{0.0};
};

}  // namespace dh3::hand
