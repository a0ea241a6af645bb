// StatusCache without DDS: a hand's status is cached once per update, in
// order, whichever of the reply and the status topic brings it first; a new
// incarnation's statuses replace the old ones; a lost service's hands go
// offline once.

#include <gtest/gtest.h>

#include "status_cache.hpp"

namespace dh3::detail {
namespace {

HandStatus status_of(const HandAddress& address, std::uint64_t update_seq, bool online = true) {
  HandStatus status;
  status.address = address;
  status.name = "left";
  status.online = online;
  status.update_seq = update_seq;
  status.position = static_cast<std::int32_t>(update_seq * 10);
  return status;
}

const HandAddress kLeft{"svc", "can0", 1};
const HandAddress kRight{"svc", "can0", 2};
const HandAddress kOther{"other", "can0", 1};

TEST(StatusCache, AnUpdateFromTheSameIncarnationIsTakenOnlyIfNewer) {
  StatusCache cache;
  EXPECT_TRUE(cache.take("A", status_of(kLeft, 5)));
  EXPECT_FALSE(cache.take("A", status_of(kLeft, 5)));  // the same sample twice (reply, topic)
  EXPECT_FALSE(cache.take("A", status_of(kLeft, 4)));  // an older one never rolls back
  ASSERT_TRUE(cache.find(kLeft));
  EXPECT_EQ(cache.find(kLeft)->update_seq, 5U);
  EXPECT_TRUE(cache.take("A", status_of(kLeft, 6)));
  EXPECT_EQ(cache.find(kLeft)->position, 60);
}

TEST(StatusCache, ANewIncarnationReplacesTheCachedStatusWhateverItsUpdateSeq) {
  StatusCache cache;
  ASSERT_TRUE(cache.take("A", status_of(kLeft, 90)));
  EXPECT_TRUE(cache.take("B", status_of(kLeft, 1)));  // update_seq restarts with the service
  EXPECT_EQ(cache.find(kLeft)->update_seq, 1U);
  EXPECT_FALSE(cache.take("B", status_of(kLeft, 1)));
}

TEST(StatusCache, ALostServiceTakesOnlyItsOnlineHandsOfflineOnce) {
  StatusCache cache;
  cache.take("A", status_of(kLeft, 1));
  cache.take("A", status_of(kRight, 1, false));
  cache.take("C", status_of(kOther, 1));
  const auto lost = cache.mark_lost("svc");
  ASSERT_EQ(lost.size(), 1U);
  EXPECT_EQ(lost[0].address, kLeft);
  EXPECT_FALSE(lost[0].online);
  EXPECT_TRUE(lost[0].service_lost);
  EXPECT_FALSE(cache.find(kLeft)->online);
  EXPECT_TRUE(cache.find(kOther)->online);
  EXPECT_TRUE(cache.mark_lost("svc").empty());  // already offline
}

TEST(StatusCache, AServiceThatAssertsAgainBringsBackOnlyTheHandsItSentAndLost) {
  StatusCache cache;
  cache.take("A", status_of(kLeft, 3));
  cache.take("A", status_of(kRight, 1, false));
  cache.take("C", status_of(kOther, 1));
  cache.mark_lost("svc");
  cache.mark_lost("other");
  EXPECT_TRUE(cache.mark_regained("B").empty()) << "another incarnation's hands stay lost";
  const auto back = cache.mark_regained("A");
  ASSERT_EQ(back.size(), 1U) << "hand 2 was offline before its service was lost";
  EXPECT_EQ(back[0].address, kLeft);
  EXPECT_TRUE(back[0].online);
  EXPECT_FALSE(back[0].service_lost);
  EXPECT_EQ(back[0].update_seq, 3U);
  EXPECT_TRUE(cache.find(kLeft)->online);
  EXPECT_FALSE(cache.find(kOther)->online);
  EXPECT_TRUE(cache.mark_regained("A").empty());  // already back
}

TEST(StatusCache, MatchingAndHasServiceLookOnlyAtWhatWasAsked) {
  StatusCache cache;
  cache.take("A", status_of(kLeft, 1));
  cache.take("A", status_of(kRight, 1));
  EXPECT_EQ(cache.all().size(), 2U);
  ASSERT_EQ(cache.matching(kRight).size(), 1U);
  EXPECT_EQ(cache.matching(kRight)[0].address, kRight);
  EXPECT_TRUE(cache.matching(kOther).empty());
  EXPECT_TRUE(cache.has_service("svc"));
  EXPECT_FALSE(cache.has_service("other"));
  EXPECT_TRUE(cache.has(kLeft));
  EXPECT_FALSE(cache.has(kOther));
}

TEST(StatusCache, KnownHandsAreThoseWithAStatusThenThoseAnInfoListsWithout) {
  StatusCache cache;
  cache.take("A", status_of(kLeft, 1));
  ServiceInfo info;
  info.name = "svc";
  BusInfo bus;
  bus.name = "can0";
  bus.hands = {HandInfo{1, "left"}, HandInfo{2, "right"}};
  info.buses.push_back(bus);
  const auto known = cache.known_hands({info});
  ASSERT_EQ(known.size(), 2U);
  EXPECT_EQ(known[0].address, kLeft);
  EXPECT_EQ(known[1].address, kRight);
  EXPECT_EQ(known[1].name, "right");
}

}  // namespace
}  // namespace dh3::detail
