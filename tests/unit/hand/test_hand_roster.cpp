// The roster is the one record of a bus's hands and their published states:
// the scheduler keeps it, and whoever needs either (the DDS side validating a
// request, listing hands, a metrics scrape) asks it.

#include <gtest/gtest.h>

#include "dh3/hand/hand_roster.hpp"
#include "unit/hand/scheduler_harness.hpp"

namespace dh3::hand::test {
namespace {

TEST(HandRoster, KnowsTheConfiguredHandsWithTheirNamesAndNeverIdZero) {
  HandRoster roster({{2, "left"}, {0, "nobody"}, {5, ""}, {2, "again"}});
  EXPECT_TRUE(roster.knows(2));
  EXPECT_TRUE(roster.knows(5));
  EXPECT_FALSE(roster.knows(0));
  EXPECT_FALSE(roster.knows(3));
  EXPECT_EQ(roster.name(2), "left");
  const auto hands = roster.hands();
  ASSERT_EQ(hands.size(), 2u);
  EXPECT_EQ(hands[0].can_id, 2);
  EXPECT_EQ(hands[1].can_id, 5);
  EXPECT_TRUE(roster.add(9));
  EXPECT_FALSE(roster.add(9));
  EXPECT_FALSE(roster.add(0));
  EXPECT_TRUE(roster.knows(9));
}

TEST(HandRoster, AHandTheBusDiscoversJoinsItsSchedulersRoster) {
  SchedulerHarness h(sim_hands({1, 7}), configs({1}));
  h.bring_up({1});
  EXPECT_FALSE(h.scheduler->roster().knows(7));
  std::optional<std::vector<std::uint8_t>> found;
  h.scheduler->request_scan([&](const std::vector<std::uint8_t>& ids) { found = ids; });
  ASSERT_TRUE(h.run_until([&] { return found.has_value(); }, 5s));
  EXPECT_TRUE(h.scheduler->roster().knows(7));
  EXPECT_EQ(h.scheduler->roster().hands().size(), 2u);
}

TEST(HandRoster, HoldsWhatTheDriversPublishedForOtherThreads) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.bring_up({1});
  const auto published = h.scheduler->roster().published();
  ASSERT_EQ(published.size(), 1u);
  EXPECT_EQ(published[0].can_id, 1);
  EXPECT_TRUE(published[0].online);
  EXPECT_EQ(h.scheduler->state().size(), 1u);
  ASSERT_FALSE(h.observer.states.empty());
  EXPECT_EQ(published[0].sequence, h.observer.states.back().sequence);
}

}  // namespace
}  // namespace dh3::hand::test
