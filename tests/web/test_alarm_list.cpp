// The console's alarm list on a clock of the test's own: conditions and
// occurrences, acknowledgement (a condition acknowledged while it lasts is
// not raised again), and the bound (the oldest acknowledged leave first).

#include "alarm_list.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>

#include "dh3/base/clock.hpp"

namespace dh3::web {
namespace {

using ::testing::ElementsAre;

/// The wall time the list is told, ns since the epoch, moved by hand.
class AlarmListTest : public ::testing::Test {
 protected:
  std::uint64_t now() const {
    return static_cast<std::uint64_t>(
        std::chrono::duration_cast<std::chrono::nanoseconds>(clock_.now().time_since_epoch())
            .count());
  }
  void later() { clock_.advance(std::chrono::seconds(1)); }

  std::vector<std::string> keys() const {
    std::vector<std::string> listed;
    for (const auto& alarm : list_.alarms()) listed.push_back(alarm.key);
    return listed;
  }

  FakeClock clock_;
  AlarmList list_{4};
};

TEST_F(AlarmListTest, AConditionIsListedWhileItLastsAndMarkedOverAfter) {
  const auto raised_at = now();
  EXPECT_TRUE(list_.holds("offline:a/bus0/4", true, "hand 4 OFFLINE", now()));
  later();
  EXPECT_FALSE(list_.holds("offline:a/bus0/4", true, "hand 4 OFFLINE", now()));
  ASSERT_EQ(list_.alarms().size(), 1U);
  const Alarm alarm = list_.alarms()[0];
  EXPECT_TRUE(alarm.condition);
  EXPECT_TRUE(alarm.active);
  EXPECT_EQ(alarm.since_ns, raised_at);
  later();
  EXPECT_TRUE(list_.holds("offline:a/bus0/4", false, "", now()));
  EXPECT_FALSE(list_.holds("offline:a/bus0/4", false, "", now()));
  const Alarm over = list_.alarms()[0];
  EXPECT_FALSE(over.active);
  EXPECT_FALSE(over.acknowledged);
  EXPECT_EQ(over.over_ns, now());
  // Back before anyone acknowledged it: the same alarm, active again.
  later();
  EXPECT_TRUE(list_.holds("offline:a/bus0/4", true, "hand 4 OFFLINE again", now()));
  ASSERT_EQ(list_.alarms().size(), 1U);
  EXPECT_EQ(list_.alarms()[0].id, alarm.id);
  EXPECT_TRUE(list_.alarms()[0].active);
  EXPECT_EQ(list_.alarms()[0].text, "hand 4 OFFLINE again");
  EXPECT_EQ(list_.alarms()[0].since_ns, now());
}

TEST_F(AlarmListTest, AConditionAcknowledgedWhileItLastsIsNotRaisedAgainUntilItComesBack) {
  list_.holds("bus:a/bus0", true, "Bus a/bus0 down", now());
  const std::uint64_t id = list_.alarms()[0].id;
  later();
  const auto acknowledged = list_.acknowledge(id, now());
  ASSERT_TRUE(acknowledged.has_value());
  EXPECT_TRUE(acknowledged->acknowledged);
  EXPECT_EQ(acknowledged->acknowledged_ns, now());
  EXPECT_FALSE(list_.holds("bus:a/bus0", true, "Bus a/bus0 down", now()));
  EXPECT_FALSE(list_.holds("bus:a/bus0", true, "Bus a/bus0 down (other words)", now()));
  ASSERT_EQ(list_.alarms().size(), 1U);
  EXPECT_TRUE(list_.alarms()[0].acknowledged);
  // It ends, and comes back: a new alarm beside the acknowledged one.
  list_.holds("bus:a/bus0", false, "", now());
  later();
  EXPECT_TRUE(list_.holds("bus:a/bus0", true, "Bus a/bus0 down", now()));
  ASSERT_EQ(list_.alarms().size(), 2U);
  EXPECT_NE(list_.alarms()[0].id, id);
  EXPECT_FALSE(list_.alarms()[0].acknowledged);
  EXPECT_TRUE(list_.alarms()[1].acknowledged);
}

TEST_F(AlarmListTest, AnOccurrenceIsListedOnceAndAcknowledgingTwiceIsHarmless) {
  EXPECT_TRUE(list_.raise_once("event:a/bus0/2:7:100", "hand 2 DROPPED", now()));
  EXPECT_FALSE(list_.raise_once("event:a/bus0/2:7:100", "hand 2 DROPPED", now()));
  ASSERT_EQ(list_.alarms().size(), 1U);
  const Alarm dropped = list_.alarms()[0];
  EXPECT_FALSE(dropped.condition);
  EXPECT_TRUE(dropped.active);
  const auto version = list_.version();
  ASSERT_TRUE(list_.acknowledge(dropped.id, now()).has_value());
  EXPECT_GT(list_.version(), version);
  const auto acknowledged_version = list_.version();
  later();
  const auto again = list_.acknowledge(dropped.id, now());
  ASSERT_TRUE(again.has_value());
  EXPECT_NE(again->acknowledged_ns, now());  // the first acknowledgement stands
  EXPECT_EQ(list_.version(), acknowledged_version);
  EXPECT_FALSE(list_.acknowledge(dropped.id + 100, now()).has_value());
}

TEST_F(AlarmListTest, NewestFirstAndTheIdsAreNeverReused) {
  list_.raise_once("command:1", "one", now());
  later();
  list_.raise_once("command:2", "two", now());
  EXPECT_THAT(keys(), ElementsAre("command:2", "command:1"));
  EXPECT_LT(list_.alarms()[1].id, list_.alarms()[0].id);
}

TEST_F(AlarmListTest, AFullListDropsTheOldestAcknowledgedFirstThenTheOldestOver) {
  list_.raise_once("command:1", "one", now());
  list_.holds("offline:a/bus0/1", true, "hand 1 OFFLINE", now());
  list_.raise_once("command:2", "two", now());
  list_.holds("offline:a/bus0/2", true, "hand 2 OFFLINE", now());
  // command:2 acknowledged, hand 1 back online (over): the list is full.
  ASSERT_TRUE(list_.acknowledge(list_.alarms()[1].id, now()).has_value());
  list_.holds("offline:a/bus0/1", false, "", now());
  list_.raise_once("command:3", "three", now());
  EXPECT_THAT(keys(),
              ElementsAre("command:3", "offline:a/bus0/2", "offline:a/bus0/1", "command:1"));
  list_.raise_once("command:4", "four", now());
  EXPECT_THAT(keys(), ElementsAre("command:4", "command:3", "offline:a/bus0/2", "command:1"));
  // Nothing acknowledged nor over: the oldest goes.
  list_.raise_once("command:5", "five", now());
  EXPECT_THAT(keys(), ElementsAre("command:5", "command:4", "command:3", "offline:a/bus0/2"));
}

TEST_F(AlarmListTest, AnAcknowledgedConditionPushedOutOfTheListIsStillNotRaisedAgain) {
  list_.holds("service:a", true, "Service a lost", now());
  ASSERT_TRUE(list_.acknowledge(list_.alarms()[0].id, now()).has_value());
  for (int i = 0; i < 4; ++i) list_.raise_once("command:" + std::to_string(i), "failed", now());
  EXPECT_THAT(keys(), ElementsAre("command:3", "command:2", "command:1", "command:0"));
  EXPECT_FALSE(list_.holds("service:a", true, "Service a lost", now()));
  EXPECT_THAT(keys(), ElementsAre("command:3", "command:2", "command:1", "command:0"));
}

}  // namespace
}  // namespace dh3::web
