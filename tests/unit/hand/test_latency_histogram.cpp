// LatencyHistogram: where a duration lands, and that a snapshot taken while
// another thread observes is consistent.

#include <gtest/gtest.h>

#include <thread>

#include "dh3/hand/latency_histogram.hpp"

namespace dh3::hand {
namespace {

using namespace std::chrono_literals;

TEST(LatencyHistogram, ADurationLandsInTheFirstBucketWhoseBoundItDoesNotExceed) {
  LatencyHistogram histogram;
  histogram.observe(20ms);        // on a bound: in it
  histogram.observe(20ms + 1us);  // just above: the next
  histogram.observe(-3ms);        // clocks of two threads: counted as 0
  histogram.observe(5s);          // above the last bound
  const LatencySnapshot snapshot = histogram.snapshot();
  EXPECT_EQ(snapshot.counts[0], 1u);
  EXPECT_EQ(kLatencyBuckets[6], 20ms);
  EXPECT_EQ(snapshot.counts[6], 1u);
  EXPECT_EQ(snapshot.counts[7], 1u);
  EXPECT_EQ(snapshot.counts.back(), 1u);
  EXPECT_EQ(snapshot.total(), 4u);
  EXPECT_NEAR(snapshot.sum_seconds, 5.040001, 1e-9);
}

TEST(LatencyHistogram, TheBoundsResolveOneToAHundredMillisecondsInOrder) {
  for (std::size_t i = 1; i < kLatencyBuckets.size(); ++i) {
    EXPECT_LT(kLatencyBuckets[i - 1], kLatencyBuckets[i]);
  }
  int within = 0;
  for (const Duration bound : kLatencyBuckets) within += bound >= 1ms && bound <= 100ms ? 1 : 0;
  EXPECT_GE(within, 12);
}

TEST(LatencyHistogram, SnapshotsWhileAnotherThreadObservesNeverLoseOrInventCounts) {
  LatencyHistogram histogram;
  constexpr int kObservations = 20000;
  std::thread writer([&] {
    for (int i = 0; i < kObservations; ++i) histogram.observe(std::chrono::microseconds(i % 3000));
  });
  std::uint64_t previous = 0;
  for (int i = 0; i < 200; ++i) {
    const std::uint64_t total = histogram.snapshot().total();
    EXPECT_GE(total, previous);
    EXPECT_LE(total, static_cast<std::uint64_t>(kObservations));
    previous = total;
  }
  writer.join();
  EXPECT_EQ(histogram.snapshot().total(), static_cast<std::uint64_t>(kObservations));
}

}  // namespace
}  // namespace dh3::hand
