#pragma once
// A histogram of durations the hand layer keeps for the metrics endpoint (it
// knows no Prometheus; service/metrics renders the snapshots on each scrape).
// Its bounds resolve 1-100 ms, where a hand's command interval (20 ms) and its
// multiples land, so a p99 read off it tells one interval from two.
//
// Threading: observe() from any thread (the bus loop, in practice) with relaxed
// atomic increments, so counting never blocks the loop; snapshot() from any
// thread, never blocking either. A snapshot taken while observations land may
// miss the newest of them, and its sum may hold one whose bucket it missed by
// a few nanoseconds' worth; its count is always the sum of its buckets, so the
// cumulative buckets it gives are consistent (monotone, +Inf = count).

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>

#include "dh3/base/clock.hpp"

namespace dh3::hand {

/// Upper bounds of every LatencyHistogram.
inline constexpr std::array<Duration, 16> kLatencyBuckets{
    std::chrono::microseconds(500), std::chrono::milliseconds(1),   std::chrono::milliseconds(2),
    std::chrono::milliseconds(5),   std::chrono::milliseconds(10),  std::chrono::milliseconds(15),
    std::chrono::milliseconds(20),  std::chrono::milliseconds(25),  std::chrono::milliseconds(30),
    std::chrono::milliseconds(40),  std::chrono::milliseconds(50),  std::chrono::milliseconds(60),
    std::chrono::milliseconds(80),  std::chrono::milliseconds(100), std::chrono::milliseconds(250),
    std::chrono::seconds(1)};

/// A LatencyHistogram's counts at one moment.
struct LatencySnapshot {
  /// Observations per bucket of kLatencyBuckets (not cumulative); the last
  /// element counts those above the largest bound.
  std::array<std::uint64_t, kLatencyBuckets.size() + 1> counts{};
  double sum_seconds = 0.0;
  [[nodiscard]] std::uint64_t total() const;
};

class LatencyHistogram {
 public:
  /// Counts one duration (a negative one, from clocks of two threads, as 0).
  void observe(Duration duration);
  [[nodiscard]] LatencySnapshot snapshot() const;

 private:
  std::array<std::atomic<std::uint64_t>, kLatencyBuckets.size() + 1> counts_{};
  std::atomic<std::uint64_t> sum_ns_{0};
};

}  // namespace dh3::hand
