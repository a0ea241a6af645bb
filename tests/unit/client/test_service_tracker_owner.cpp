// ServiceTracker with owner claims (idl/dh3_ownership.hpp), without DDS: the
// owner is believed and nothing else of its name; an owner whose liveliness
// lapses is lost at once, and found again when it asserts again.

#include <gtest/gtest.h>

#include "service_tracker.hpp"

namespace dh3::detail {
namespace {

using Endpoint = ServiceTracker::Endpoint;
using Outcome = ServiceTracker::Outcome;

contract::OwnerClaim claim(const std::string& participant, std::uint64_t epoch,
                           std::uint64_t started_ns) {
  contract::OwnerClaim c;
  c.participant = participant;
  c.service = "svc";
  c.host = "pc-" + participant;
  c.pid = 42;
  c.started_ns = started_ns;
  c.epoch = epoch;
  return c;
}

/// `prefix` serves svc: its claim arrived and it asserts its liveliness.
void serve(ServiceTracker& tracker, const std::string& prefix, std::uint64_t epoch,
           std::uint64_t started_ns) {
  Outcome ignored;
  tracker.take_claim(claim(prefix, epoch, started_ns), ignored);
  tracker.owner_alive(prefix, true);
}

TEST(TrackerOwner, ALapsedLivelinessLosesTheServiceAtOnceSayingWhy) {
  ServiceTracker tracker;
  Outcome ignored;
  tracker.note_participant("A", "svc", ignored);
  serve(tracker, "A", 1, 10);
  EXPECT_EQ(tracker.incarnation("svc"), "A");
  EXPECT_TRUE(tracker.alive("svc"));
  const Outcome lapsed = tracker.owner_alive("A", false);
  EXPECT_TRUE(lapsed.lost_service);
  EXPECT_EQ(lapsed.lost, "A");
  EXPECT_NE(lapsed.why.find("stopped asserting it lives"), std::string::npos) << lapsed.why;
  EXPECT_NE(lapsed.why.find("killed, frozen or cut off"), std::string::npos) << lapsed.why;
  EXPECT_NE(lapsed.why.find("pc-A"), std::string::npos) << lapsed.why;
  EXPECT_FALSE(tracker.alive("svc"));
  // What it still sends (it is frozen, or cut off and back) is not believed.
  Outcome late;
  EXPECT_FALSE(tracker.note_participant("A", "svc", late));
  EXPECT_FALSE(tracker.believed("A", "svc"));
}

TEST(TrackerOwner, AnOwnerThatAssertsAgainIsServedAgain) {
  ServiceTracker tracker;
  serve(tracker, "A", 1, 10);
  tracker.owner_alive("A", false);
  const Outcome back = tracker.owner_alive("A", true);
  EXPECT_FALSE(back.lost_service);
  EXPECT_TRUE(back.may_dispatch);
  EXPECT_TRUE(tracker.alive("svc"));
  EXPECT_EQ(tracker.incarnation("svc"), "A");
  EXPECT_TRUE(tracker.believed("A", "svc"));
}

TEST(TrackerOwner, ADuplicateIsNeverBelievedNorMadeCurrent) {
  ServiceTracker tracker;
  serve(tracker, "A", 1, 10);
  Outcome dup;
  // A second service of the name in its claim window: a participant, no claim.
  EXPECT_FALSE(tracker.note_participant("B", "svc", dup));
  EXPECT_FALSE(tracker.believed("B", "svc"));
  ServiceInfo info;
  info.name = "svc";
  info.started_ns = 999;  // started later: before claims, that was a restart
  EXPECT_FALSE(tracker.take_info("B", info, dup));
  EXPECT_FALSE(dup.lost_service);
  EXPECT_EQ(tracker.incarnation("svc"), "A");
  // Even once the owner died, the refused one does not become the service.
  tracker.owner_alive("A", false);
  EXPECT_FALSE(tracker.note_participant("A", "svc", dup));
  EXPECT_NE(tracker.incarnation("svc"), "B");
}

TEST(TrackerOwner, AHigherEpochTakesOverAndTheOldOwnersCallsAreLost) {
  ServiceTracker tracker;
  serve(tracker, "A", 1, 10);
  Outcome ignored;
  tracker.take_claim(claim("B", 2, 5), ignored);
  EXPECT_EQ(tracker.incarnation("svc"), "A") << "B's liveliness not seen yet";
  const Outcome taken = tracker.owner_alive("B", true);
  EXPECT_TRUE(taken.lost_service);
  EXPECT_EQ(taken.lost, "A");
  EXPECT_NE(taken.why.find("now served by"), std::string::npos) << taken.why;
  EXPECT_EQ(tracker.incarnation("svc"), "B");
  EXPECT_FALSE(tracker.believed("A", "svc"));
  EXPECT_TRUE(tracker.believed("B", "svc"));
}

TEST(TrackerOwner, AStandbyIsNotBelievedWhileItStandsBy) {
  ServiceTracker tracker;
  serve(tracker, "A", 1, 10);
  auto standby = claim("S", 1, 20);
  standby.standby = true;
  Outcome ignored;
  tracker.take_claim(standby, ignored);
  tracker.owner_alive("S", true);
  EXPECT_EQ(tracker.incarnation("svc"), "A");
  EXPECT_FALSE(tracker.believed("S", "svc"));
  // The primary dies: nobody serves until the standby claims as active.
  tracker.owner_alive("A", false);
  EXPECT_FALSE(tracker.alive("svc"));
  standby.standby = false;
  standby.epoch = 2;
  Outcome takeover;
  tracker.take_claim(standby, takeover);
  EXPECT_TRUE(takeover.may_dispatch);
  EXPECT_EQ(tracker.incarnation("svc"), "S");
  EXPECT_TRUE(tracker.alive("svc"));
}

TEST(TrackerOwner, TheOwnerLeavingHandsTheNameToTheNextLiveOwner) {
  ServiceTracker tracker;
  serve(tracker, "A", 2, 10);
  serve(tracker, "B", 1, 10);
  EXPECT_EQ(tracker.incarnation("svc"), "A");
  const Outcome left = tracker.participant_left("A");
  EXPECT_TRUE(left.lost_service);
  EXPECT_EQ(tracker.incarnation("svc"), "B");
  EXPECT_TRUE(tracker.alive("svc"));
}

}  // namespace
}  // namespace dh3::detail
