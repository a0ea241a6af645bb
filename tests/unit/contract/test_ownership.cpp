// The ownership rule (idl/include/dh3/contract/ownership.hpp) without DDS: who owns a cell
// name, what a service decides at start, and how two owners that meet after
// a partition agree on the one that stops.

#include <gtest/gtest.h>

#include "dh3/contract/ownership.hpp"

namespace dh3::contract {
namespace {

using namespace std::chrono_literals;

OwnerClaim claim(const std::string& participant, std::uint64_t epoch, std::uint64_t started_ns,
                 bool standby = false, const std::string& service = "cell") {
  OwnerClaim c;
  c.participant = participant;
  c.service = service;
  c.host = "host-" + participant;
  c.pid = 100;
  c.started_ns = started_ns;
  c.epoch = epoch;
  c.standby = standby;
  return c;
}

TEST(OwnerTable, TheOwnerIsALiveActiveClaimantAndNothingElse) {
  OwnerTable table;
  EXPECT_FALSE(table.owner("cell"));
  table.claim(claim("a", 1, 10));
  ASSERT_TRUE(table.owner("cell")) << "its liveliness not seen yet: unknown is not dead";
  EXPECT_FALSE(table.alive("a"));
  EXPECT_FALSE(table.lapsed("a"));
  table.set_alive("a", true);
  ASSERT_TRUE(table.owner("cell"));
  EXPECT_EQ(table.owner("cell")->participant, "a");
  EXPECT_TRUE(table.alive("a"));
  EXPECT_FALSE(table.owner("other"));
  table.set_alive("a", false);
  EXPECT_FALSE(table.owner("cell")) << "its lease lapsed: killed, frozen or cut off";
  EXPECT_TRUE(table.lapsed("a"));
  table.set_alive("a", true);
  EXPECT_EQ(table.owner("cell")->participant, "a") << "asserting again, it owns again";
  table.forget("a");
  EXPECT_FALSE(table.owner("cell"));
}

TEST(OwnerTable, LivelinessMayComeBeforeTheClaim) {
  OwnerTable table;
  table.set_alive("a", true);
  EXPECT_FALSE(table.owner("cell"));
  table.claim(claim("a", 1, 10));
  EXPECT_EQ(table.owner("cell")->participant, "a");
}

TEST(OwnerTable, LivelinessChangesSayTheWritersStateInWhateverOrderTheyCame) {
  OwnerTable table;
  EXPECT_TRUE(table.liveliness_changed("a", +1)) << "first assertion";
  // A lapse and the assertion that ended it, reported the wrong way round.
  EXPECT_TRUE(table.liveliness_changed("a", +1));
  EXPECT_TRUE(table.liveliness_changed("a", -1)) << "the late lapse: it asserted since";
  EXPECT_FALSE(table.liveliness_changed("a", -1)) << "a lapse in order";
  // Its first assertion was never reported: the lapse after it brings the
  // sum to no less than 0, and the next assertion says alive.
  EXPECT_FALSE(table.liveliness_changed("c", -1));
  EXPECT_TRUE(table.liveliness_changed("c", +1));
  EXPECT_FALSE(table.liveliness_changed("b", -1)) << "each writer its own sum";
  EXPECT_FALSE(table.liveliness_changed("a", 0)) << "no change: still lapsed";
  table.liveliness_changed("a", +1);
  table.liveliness_changed("a", +1);  // a report the wrong way round, never undone
  table.forget("a");
  EXPECT_TRUE(table.liveliness_changed("a", +1)) << "found again after it left: a new sum";
  EXPECT_FALSE(table.liveliness_changed("a", -1));
}

TEST(OwnerTable, AStandbyNeverOwns) {
  OwnerTable table;
  table.claim(claim("s", 5, 10, /*standby=*/true));
  table.set_alive("s", true);
  EXPECT_FALSE(table.owner("cell"));
  table.claim(claim("a", 1, 20));
  table.set_alive("a", true);
  EXPECT_EQ(table.owner("cell")->participant, "a");
}

TEST(OwnerTable, HighestEpochCountsDeadClaimsToo) {
  OwnerTable table;
  EXPECT_EQ(table.highest_epoch("cell"), 0U);
  table.claim(claim("a", 4, 10));
  table.claim(claim("b", 2, 10));
  table.set_alive("b", true);
  EXPECT_EQ(table.highest_epoch("cell"), 4U);
  EXPECT_EQ(table.highest_epoch("other"), 0U);
}

TEST(Outranks, EpochThenLaterStartThenParticipant) {
  EXPECT_TRUE(outranks(claim("a", 2, 10), claim("b", 1, 99)));
  EXPECT_FALSE(outranks(claim("b", 1, 99), claim("a", 2, 10)));
  EXPECT_TRUE(outranks(claim("a", 1, 20), claim("b", 1, 10)));
  EXPECT_TRUE(outranks(claim("b", 1, 10), claim("a", 1, 10)));
  EXPECT_FALSE(outranks(claim("a", 1, 10), claim("a", 1, 10)));
}

TEST(Outranks, TwoOwnersThatMeetAfterAPartitionAgreeOnOne) {
  // Each side judges with the same two claims; exactly one of them stops.
  const OwnerClaim left = claim("0a", 1, 500);
  const OwnerClaim right = claim("0b", 1, 500);
  OwnerTable seen_by_left;
  OwnerTable seen_by_right;
  for (OwnerTable* table : {&seen_by_left, &seen_by_right}) {
    table->claim(left);
    table->claim(right);
    table->set_alive(left.participant, true);
    table->set_alive(right.participant, true);
  }
  const auto left_owner = seen_by_left.owner("cell");
  const auto right_owner = seen_by_right.owner("cell");
  ASSERT_TRUE(left_owner && right_owner);
  EXPECT_EQ(left_owner->participant, right_owner->participant);
  EXPECT_NE(outranks(left, right), outranks(right, left));
}

TEST(StartClaim, ServesOnlyOnceTheWindowHasPassedWithoutAnOwner) {
  FakeClock clock;
  OwnerTable table;
  StartClaim start("cell", "self", 1800ms, clock);
  EXPECT_EQ(start.decide(table), StartClaim::Verdict::wait);
  clock.advance(1799ms);
  EXPECT_EQ(start.decide(table), StartClaim::Verdict::wait);
  clock.advance(1ms);
  EXPECT_EQ(start.decide(table), StartClaim::Verdict::serve);
  EXPECT_EQ(start.epoch(table), 1U);
}

TEST(StartClaim, WaitsPastTheWindowForTheClaimOfAServiceOfItsNameThatWasAnnounced) {
  // A loaded machine: the owner's participant is discovered, its claim
  // sample has not arrived when the window ends.
  FakeClock clock;
  OwnerTable table;
  StartClaim start("cell", "self", 1800ms, clock);
  table.announced("owner", "cell");
  table.announced("elsewhere", "other-cell");
  clock.advance(1800ms);
  EXPECT_EQ(start.decide(table), StartClaim::Verdict::wait);
  clock.advance(1000ms);
  table.claim(claim("owner", 1, 10));
  EXPECT_EQ(start.decide(table), StartClaim::Verdict::refuse);
  EXPECT_EQ(start.other()->participant, "owner");
}

TEST(StartClaim, AnAnnouncedServiceThatNeverClaimsDelaysTheStartABoundedTime) {
  // A service without an owner writer, or one that died after it was announced.
  FakeClock clock;
  OwnerTable table;
  StartClaim start("cell", "self", 1800ms, clock);
  table.announced("silent", "cell");
  clock.advance(1800ms + kStartClaimAwait - 1ms);
  EXPECT_EQ(start.decide(table), StartClaim::Verdict::wait);
  clock.advance(1ms);
  EXPECT_EQ(start.decide(table), StartClaim::Verdict::serve);
  // One that left the domain is not waited for.
  StartClaim again("cell", "self", 1800ms, clock);
  table.forget("silent");
  clock.advance(1800ms);
  EXPECT_EQ(again.decide(table), StartClaim::Verdict::serve);
}

TEST(StartClaim, RefusesAtOnceWhenALiveOwnerAppearsAndNamesIt) {
  FakeClock clock;
  OwnerTable table;
  StartClaim start("cell", "self", 1800ms, clock);
  clock.advance(300ms);
  table.claim(claim("lapsed", 5, 10));
  table.set_alive("lapsed", true);
  table.set_alive("lapsed", false);
  EXPECT_EQ(start.decide(table), StartClaim::Verdict::wait) << "a lapsed owner does not refuse";
  // A claim sample comes from a live writer: refused before its first assertion.
  table.claim(claim("other", 3, 10));
  EXPECT_EQ(start.decide(table), StartClaim::Verdict::refuse);
  ASSERT_TRUE(start.other());
  EXPECT_EQ(start.other()->participant, "other");
  EXPECT_NE(start.other()->describe().find("host-other"), std::string::npos);
  EXPECT_NE(start.other()->describe().find("pid 100"), std::string::npos);
}

TEST(StartClaim, AKilledPredecessorIsSupersededWithAHigherEpoch) {
  FakeClock clock;
  OwnerTable table;
  // The old instance's claim arrived, its liveliness lapsed (killed, or frozen).
  table.claim(claim("old", 4, 10));
  table.set_alive("old", true);
  table.set_alive("old", false);
  StartClaim start("cell", "self", 1800ms, clock);
  clock.advance(1800ms);
  EXPECT_EQ(start.decide(table), StartClaim::Verdict::serve);
  const std::uint64_t epoch = start.epoch(table);
  EXPECT_EQ(epoch, 5U);
  // Should the frozen one resume, the new one outranks it whatever the clocks say.
  EXPECT_TRUE(outranks(claim("self", epoch, 1), claim("old", 4, 10)));
}

TEST(StartClaim, ItsOwnClaimAndOtherNamesDoNotCount) {
  FakeClock clock;
  OwnerTable table;
  table.claim(claim("self", 1, 10));
  table.set_alive("self", true);
  table.claim(claim("x", 1, 10, false, "another-cell"));
  table.set_alive("x", true);
  StartClaim start("cell", "self", 100ms, clock);
  clock.advance(100ms);
  EXPECT_EQ(start.decide(table), StartClaim::Verdict::serve);
}

TEST(StartClaim, TheWindowOutlastsTheOwnerLease) {
  // A service killed just before a new one starts is seen dead in the window.
  EXPECT_GT(kStartClaimWindow, kOwnerLease);
  // Seven assertion periods fit in a lease: a 200 ms network stall, or a
  // service starved for half a second, is no false alarm.
  EXPECT_GE(kOwnerLease / kOwnerAssertPeriod, 7);
  // A death is still believed within the second.
  EXPECT_LE(kOwnerLease + kOwnerLapseConfirm, std::chrono::milliseconds(900));
}

}  // namespace
}  // namespace dh3::contract
