// The discovery scan: which CAN ID is probed when, what an answer or a silence
// means, and when a scan starts and ends. Time is a FakeClock moved by the test.

#include <gtest/gtest.h>

#include <chrono>
#include <optional>
#include <vector>

#include "discovery_scan.hpp"

namespace dh3::hand {
namespace {

using namespace std::chrono_literals;

DiscoveryOptions options(bool periodic = true, Duration interval = 2s) {
  return DiscoveryOptions{periodic, interval, 1ms, 150ms};
}

class DiscoveryScanTest : public ::testing::Test {
 protected:
  /// Probes what is due now, as the scheduler does with no line budget.
  std::vector<std::uint8_t> send_due(DiscoveryScan& scan) {
    std::vector<std::uint8_t> sent;
    while (const auto id = scan.due_probe(clock_.now())) {
      sent.push_back(*id);
      if (!scan.probe_sent(clock_.now(), clock_.now())) break;
    }
    return sent;
  }
  /// Runs passes 1 ms apart until the scan completes; the IDs probed.
  std::vector<std::uint8_t> run_to_completion(DiscoveryScan& scan) {
    std::vector<std::uint8_t> probed;
    for (int pass = 0; pass < 1000; ++pass) {
      if (scan.on_time(clock_.now(), true) == ScanTick::complete) return probed;
      for (std::uint8_t id : send_due(scan)) probed.push_back(id);
      clock_.advance(1ms);
    }
    ADD_FAILURE() << "the scan did not complete";
    return probed;
  }

  FakeClock clock_;
};

TEST_F(DiscoveryScanTest, ABusWithConfiguredHandsScansOnlyWhenAsked) {
  DiscoveryScan scan(options(false), clock_.now());
  EXPECT_EQ(scan.on_time(clock_.now(), true), ScanTick::idle);
  EXPECT_FALSE(scan.active());
  EXPECT_FALSE(scan.next_wakeup());
  EXPECT_FALSE(scan.due_probe(clock_.now()));
  EXPECT_TRUE(scan.request([](const auto&) {}, clock_.now()));
  EXPECT_TRUE(scan.active());
  EXPECT_EQ(scan.due_probe(clock_.now()), 1);
}

TEST_F(DiscoveryScanTest, APeriodicScanStartsAtOnceButOnlyOnAnUpLink) {
  DiscoveryScan scan(options(), clock_.now());
  EXPECT_EQ(scan.on_time(clock_.now(), false), ScanTick::idle);
  EXPECT_EQ(scan.on_time(clock_.now(), true), ScanTick::started);
  EXPECT_EQ(scan.on_time(clock_.now(), true), ScanTick::probing);
}

TEST_F(DiscoveryScanTest, EveryUnknownIdIsProbedOncePerSpacingInOrder) {
  DiscoveryScan scan(options(), clock_.now());
  scan.known(2);
  scan.known(3);
  scan.known(255);
  ASSERT_EQ(scan.on_time(clock_.now(), true), ScanTick::started);
  EXPECT_EQ(send_due(scan), (std::vector<std::uint8_t>{1}));
  EXPECT_TRUE(send_due(scan).empty());  // the spacing holds the next
  clock_.advance(999us);
  EXPECT_TRUE(send_due(scan).empty());
  clock_.advance(1us);
  EXPECT_EQ(send_due(scan), (std::vector<std::uint8_t>{4}));
  const auto rest = run_to_completion(scan);
  ASSERT_EQ(rest.size(), 250u);  // 5-254
  EXPECT_EQ(rest.front(), 5);
  EXPECT_EQ(rest.back(), 254);
}

TEST_F(DiscoveryScanTest, WithoutSpacingAllProbesGoInOnePass) {
  DiscoveryScan scan(DiscoveryOptions{true, 2s, Duration::zero(), 150ms}, clock_.now());
  ASSERT_EQ(scan.on_time(clock_.now(), true), ScanTick::started);
  EXPECT_EQ(send_due(scan).size(), 255u);
}

TEST_F(DiscoveryScanTest, AnAnswerGivesWhenItsProbeLeft) {
  DiscoveryScan scan(options(), clock_.now());
  ASSERT_EQ(scan.on_time(clock_.now(), true), ScanTick::started);
  const TimePoint left = clock_.now() + 300us;  // the send took a while
  ASSERT_EQ(scan.due_probe(clock_.now()), 1);
  scan.probe_sent(clock_.now(), left);
  clock_.advance(2ms);
  EXPECT_FALSE(scan.answered(2));  // not probed yet
  EXPECT_EQ(scan.answered(1), left);
  EXPECT_FALSE(scan.answered(1));  // answered once
}

TEST_F(DiscoveryScanTest, AProbeUnansweredWithinTheReplyTimeoutFoundNothing) {
  DiscoveryScan scan(options(), clock_.now());
  ASSERT_EQ(scan.on_time(clock_.now(), true), ScanTick::started);
  ASSERT_EQ(send_due(scan).size(), 1u);
  clock_.advance(150ms);
  scan.on_time(clock_.now(), true);
  EXPECT_FALSE(scan.answered(1));
}

TEST_F(DiscoveryScanTest, ItCompletesWhenTheLastProbeTimesOutAndRepeatsAfterTheInterval) {
  DiscoveryScan scan(options(), clock_.now());
  ASSERT_EQ(scan.on_time(clock_.now(), true), ScanTick::started);
  run_to_completion(scan);
  const TimePoint completed = clock_.now();
  scan.finish({3, 40});
  EXPECT_FALSE(scan.active());
  EXPECT_EQ(scan.next_wakeup(), completed + 2s);
  clock_.set(completed + 2s - 1ms);
  EXPECT_EQ(scan.on_time(clock_.now(), true), ScanTick::idle);
  clock_.advance(1ms);
  EXPECT_EQ(scan.on_time(clock_.now(), true), ScanTick::started);
}

TEST_F(DiscoveryScanTest, AZeroIntervalScansOnce) {
  DiscoveryScan scan(options(true, Duration::zero()), clock_.now());
  ASSERT_EQ(scan.on_time(clock_.now(), true), ScanTick::started);
  run_to_completion(scan);
  scan.finish({});
  EXPECT_FALSE(scan.next_wakeup());
  clock_.advance(1h);
  EXPECT_EQ(scan.on_time(clock_.now(), true), ScanTick::idle);
}

TEST_F(DiscoveryScanTest, EveryoneWhoAskedHearsTheResultOnce) {
  DiscoveryScan scan(options(false), clock_.now());
  std::vector<std::vector<std::uint8_t>> heard;
  EXPECT_TRUE(scan.request([&](const auto& found) { heard.push_back(found); }, clock_.now()));
  clock_.advance(5ms);
  EXPECT_FALSE(scan.request([&](const auto& found) { heard.push_back(found); }, clock_.now()));
  scan.finish({1, 9});
  scan.finish({2});  // no scan runs: nobody hears it
  ASSERT_EQ(heard.size(), 2u);
  EXPECT_EQ(heard[0], (std::vector<std::uint8_t>{1, 9}));
  EXPECT_EQ(heard[1], (std::vector<std::uint8_t>{1, 9}));
}

TEST_F(DiscoveryScanTest, HeldProbesWaitAndTheWakeupSaysWhen) {
  DiscoveryScan scan(options(false), clock_.now());
  scan.request([](const auto&) {}, clock_.now());
  EXPECT_EQ(scan.next_wakeup(), clock_.now());
  scan.hold_until(clock_.now() + 20ms);
  EXPECT_EQ(scan.next_wakeup(), clock_.now() + 20ms);
  EXPECT_FALSE(scan.due_probe(clock_.now() + 19ms));
  EXPECT_EQ(scan.due_probe(clock_.now() + 20ms), 1);
  // A hold never brings the next probe forward.
  scan.hold_until(clock_.now());
  EXPECT_EQ(scan.next_wakeup(), clock_.now() + 20ms);
}

TEST_F(DiscoveryScanTest, OnceAllIdsAreProbedTheWakeupIsTheFirstDeadline) {
  DiscoveryScan scan(DiscoveryOptions{false, 2s, Duration::zero(), 150ms}, clock_.now());
  scan.request([](const auto&) {}, clock_.now());
  const TimePoint sent = clock_.now();
  ASSERT_EQ(send_due(scan).size(), 255u);
  EXPECT_EQ(scan.next_wakeup(), sent + 150ms);
  clock_.advance(150ms);
  EXPECT_EQ(scan.on_time(clock_.now(), true), ScanTick::complete);
}

TEST_F(DiscoveryScanTest, ALinkThatComesBackScansAgainAtOnce) {
  DiscoveryScan scan(options(), clock_.now());
  ASSERT_EQ(scan.on_time(clock_.now(), true), ScanTick::started);
  scan.finish({});  // the link went down
  clock_.advance(100ms);
  scan.on_link_up(clock_.now());
  EXPECT_EQ(scan.next_wakeup(), clock_.now());
  EXPECT_EQ(scan.on_time(clock_.now(), true), ScanTick::started);
}

}  // namespace
}  // namespace dh3::hand
