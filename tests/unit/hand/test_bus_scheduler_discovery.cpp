// A bus that lists no hands finds them by probing IDs 1-255 (a firmware-version
// read per ID), serves those that answer, finds hands plugged in later, and
// answers a scan requested at any time. Configured hands are never starved.

#include <gtest/gtest.h>

#include "unit/hand/scheduler_harness.hpp"

namespace dh3::hand::test {
namespace {

std::vector<std::uint8_t> online_ids(const BusScheduler& scheduler) {
  std::vector<std::uint8_t> ids;
  for (const auto& s : scheduler.state()) {
    if (s.online) ids.push_back(s.can_id);
  }
  return ids;
}

TEST(BusSchedulerDiscovery, AnEmptyHandListIsFilledByProbingEveryId) {
  SchedulerHarness h(sim_hands({3, 40, 255}), {});
  const TimePoint start = h.clock.now();
  ASSERT_TRUE(h.run_until([&] { return online_ids(*h.scheduler).size() == 3; }, 5s));
  EXPECT_EQ(online_ids(*h.scheduler), (std::vector<std::uint8_t>{3, 40, 255}));
  // Spread at 1 ms per ID: the whole probe takes well under a second.
  EXPECT_LT(h.clock.now() - start, 1s);
  std::size_t probes = 0;
  for (const auto& s : h.recorder().sent) probes += s.message.reg == reg::kFirmwareVersion;
  EXPECT_GE(probes, 255u);
  EXPECT_TRUE(h.call(40, cmd(CommandKind::initialize))->ok());
}

TEST(BusSchedulerDiscovery, AHandPluggedInLaterAppearsOnItsOwn) {
  auto options = test_options();
  options.discovery_interval = 2s;
  SchedulerHarness h(sim_hands({1}), {}, options);
  ASSERT_TRUE(h.run_until([&] { return online_ids(*h.scheduler).size() == 1; }, 5s));
  h.sim_bus().add_hand(sim_hand(7));
  ASSERT_TRUE(h.run_until([&] { return online_ids(*h.scheduler).size() == 2; }, 10s));
  EXPECT_EQ(online_ids(*h.scheduler), (std::vector<std::uint8_t>{1, 7}));
  EXPECT_EQ(h.observer.events_of(EventKind::online, 7).size(), 1u);
}

TEST(BusSchedulerDiscovery, ARequestedScanReportsEveryHandThatAnswers) {
  SchedulerHarness h(sim_hands({1, 2}), configs({1}));
  h.bring_up({1});
  h.sim_bus().add_hand(sim_hand(9));
  std::optional<std::vector<std::uint8_t>> found;
  h.scheduler->request_scan([&](const std::vector<std::uint8_t>& ids) { found = ids; });
  ASSERT_TRUE(h.run_until([&] { return found.has_value(); }, 5s));
  EXPECT_EQ(*found, (std::vector<std::uint8_t>{1, 2, 9}));
  EXPECT_TRUE(h.call(9, read(reg::kFirmwareVersion))->ok());
}

TEST(BusSchedulerDiscovery, ConfiguredHandsAreServedWhileAScanRuns) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.bring_up({1});
  std::optional<std::vector<std::uint8_t>> found;
  h.scheduler->request_scan([&](const std::vector<std::uint8_t>& ids) { found = ids; });
  h.run_for(2ms);
  // Submitted while the probe is under way, answered long before it ends.
  const auto moved = h.call(1, move(30));
  ASSERT_TRUE(moved && moved->ok());
  EXPECT_FALSE(found.has_value());
  ASSERT_TRUE(h.run_until([&] { return found.has_value(); }, 5s));
}

TEST(BusSchedulerDiscovery, AScanOnADownLinkFindsNothingAtOnce) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.bring_up({1});
  h.sim_bus().set_link_up(false);
  h.run_for(5ms);
  std::optional<std::vector<std::uint8_t>> found;
  h.scheduler->request_scan([&](const std::vector<std::uint8_t>& ids) { found = ids; });
  h.run_for(5ms);
  ASSERT_TRUE(found.has_value());
  EXPECT_TRUE(found->empty());
}

}  // namespace
}  // namespace dh3::hand::test
