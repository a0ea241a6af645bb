// PrimaryWatch: when a standby judges its active service lost, or its cell
// vacant, on a fake clock and the ownership rule's table.

#include <gtest/gtest.h>

#include "primary_watch.hpp"

namespace dh3::dds {
namespace {

using namespace std::chrono_literals;

contract::OwnerClaim claim(const std::string& participant, bool standby, std::uint64_t epoch,
                           std::uint64_t started_ns = 0) {
  contract::OwnerClaim made;
  made.participant = participant;
  made.service = "cell";
  made.host = "pc1";
  made.pid = 42;
  made.standby = standby;
  made.epoch = epoch;
  made.started_ns = started_ns;
  return made;
}

/// What the owner topic shows of "cell" in `table`.
OwnerView view_of(const contract::OwnerTable& table) {
  return {table.owner("cell"), table.highest_epoch("cell"), table.standbys("cell"),
          table.claim_awaited("cell")};
}

class PrimaryWatchTest : public ::testing::Test {
 protected:
  void SetUp() override {
    table.claim(claim("aa", /*standby=*/false, 3));
    table.set_alive("aa", true);
    table.claim(claim("bb", /*standby=*/true, 0));  // the standby itself
    table.set_alive("bb", true);
  }
  std::optional<PrimaryLapse> look() { return watch.look(view_of(table), clock.now()); }

  FakeClock clock;
  contract::OwnerTable table;
  /// The standby "bb", which takes over only from an owner it saw.
  PrimaryWatch watch{claim("bb", true, 0), clock.now(), std::nullopt};
};

TEST_F(PrimaryWatchTest, ALapseIsBelievedOnceItStoodTheClientsConfirmation) {
  EXPECT_FALSE(look());
  table.set_alive("aa", false);
  const TimePoint lapsed = clock.now();
  EXPECT_FALSE(look());
  clock.advance(contract::kOwnerLapseConfirm - 1ms);
  EXPECT_FALSE(look());
  clock.advance(1ms);
  const auto lost = look();
  ASSERT_TRUE(lost);
  ASSERT_TRUE(lost->primary);
  EXPECT_EQ(lost->primary->participant, "aa");
  EXPECT_EQ(lost->since, lapsed);
  EXPECT_EQ(lost->epoch, 3u);  // the takeover claims above it
}

TEST_F(PrimaryWatchTest, ABusReadSilentAfterTheLapseBeganConfirmsItAtOnce) {
  EXPECT_FALSE(watch.look(view_of(table), clock.now(), clock.now()));
  table.set_alive("aa", false);
  const TimePoint lapsed = clock.now();
  // Silent before the lapse was seen: not yet the buses' word on it.
  EXPECT_FALSE(watch.look(view_of(table), clock.now(), lapsed - 1ms));
  clock.advance(20ms);
  const auto lost = watch.look(view_of(table), clock.now(), clock.now());
  ASSERT_TRUE(lost);
  EXPECT_EQ(lost->since, lapsed);
}

TEST_F(PrimaryWatchTest, BusesSilentDoNotMakeALiveOwnerLost) {
  EXPECT_FALSE(watch.look(view_of(table), clock.now(), clock.now()));
  clock.advance(1s);
  EXPECT_FALSE(watch.look(view_of(table), clock.now(), clock.now()));
}

TEST_F(PrimaryWatchTest, ALapseOverturnedInTimeIsForgotten) {
  EXPECT_FALSE(look());
  table.set_alive("aa", false);
  EXPECT_FALSE(look());
  clock.advance(100ms);
  table.set_alive("aa", true);  // a frozen owner that continued
  EXPECT_FALSE(look());
  clock.advance(1s);
  EXPECT_FALSE(look());
  // A later lapse is timed from its own start.
  table.set_alive("aa", false);
  EXPECT_FALSE(look());
  clock.advance(contract::kOwnerLapseConfirm);
  EXPECT_TRUE(look());
}

TEST_F(PrimaryWatchTest, AnOwnerThatLeftIsLostToo) {
  EXPECT_FALSE(look());
  table.forget("aa");  // a clean stop: its owner writer is gone
  EXPECT_FALSE(look());
  clock.advance(contract::kOwnerLapseConfirm);
  EXPECT_TRUE(look());
}

TEST_F(PrimaryWatchTest, AStandbyThatNeverSawAnOwnerNeverJudgesOneLost) {
  table.forget("aa");
  EXPECT_FALSE(look());
  clock.advance(10s);
  EXPECT_FALSE(look());
}

TEST_F(PrimaryWatchTest, ANewOwnerIsWatchedInstead) {
  bool changed = false;
  EXPECT_FALSE(watch.look(view_of(table), clock.now(), std::nullopt, &changed));
  EXPECT_TRUE(changed);
  EXPECT_FALSE(watch.look(view_of(table), clock.now(), std::nullopt, &changed));
  EXPECT_FALSE(changed);
  table.claim(claim("cc", /*standby=*/false, 4));  // took the name over
  EXPECT_FALSE(watch.look(view_of(table), clock.now(), std::nullopt, &changed));
  EXPECT_TRUE(changed);
  table.set_alive("cc", true);
  table.set_alive("cc", false);
  clock.advance(contract::kOwnerLapseConfirm);
  EXPECT_FALSE(look());  // "aa" still lives: it owns again
}

/// A standby with a vacancy wait ("bb", started at 100 ns), beside nobody.
class VacancyTest : public ::testing::Test {
 protected:
  static constexpr auto kWait = contract::kStartClaimWindow;
  void SetUp() override {
    table.claim(self);
    table.set_alive("bb", true);
  }
  std::optional<PrimaryLapse> look() { return watch.look(view_of(table), clock.now()); }

  FakeClock clock;
  contract::OwnerTable table;
  contract::OwnerClaim self = claim("bb", /*standby=*/true, 0, 100);
  PrimaryWatch watch{self, clock.now(), kWait};
};

TEST_F(VacancyTest, ACellNobodyServedIsTakenOnceTheWaitEnded) {
  table.claim(claim("old", /*standby=*/false, 5));  // a primary that died before we came
  table.set_alive("old", false);
  const TimePoint due = clock.now() + kWait;
  clock.advance(kWait - 1ms);
  EXPECT_FALSE(look());
  clock.advance(1ms);
  const auto vacant = look();
  ASSERT_TRUE(vacant);
  EXPECT_FALSE(vacant->primary) << "nobody served the cell";
  EXPECT_EQ(vacant->since, due);
  EXPECT_EQ(vacant->epoch, 5u);  // the cell is taken above the dead primary's epoch
}

TEST_F(VacancyTest, AnOwnerSeenInTheWaitIsStoodByInstead) {
  clock.advance(kWait / 2);
  table.claim(claim("aa", /*standby=*/false, 1));
  EXPECT_FALSE(look());
  clock.advance(kWait);
  EXPECT_FALSE(look()) << "the owner lives: a standby for it";
  table.set_alive("aa", true);
  table.set_alive("aa", false);
  EXPECT_FALSE(look());
  clock.advance(contract::kOwnerLapseConfirm);
  const auto lost = look();
  ASSERT_TRUE(lost);
  ASSERT_TRUE(lost->primary) << "a takeover from the owner seen, not a vacancy";
  EXPECT_EQ(lost->primary->participant, "aa");
}

TEST_F(VacancyTest, AnAnnouncedClaimantIsAwaitedForTheStartersAwaitAtMost) {
  table.announced("slow", "cell");  // its claim sample has not arrived
  clock.advance(kWait);
  EXPECT_FALSE(look());
  clock.advance(contract::kStartClaimAwait - 1ms);
  EXPECT_FALSE(look());
  clock.advance(1ms);
  EXPECT_TRUE(look()) << "a participant that never claims does not hold the cell for ever";
}

TEST_F(VacancyTest, AClaimArrivingInTheAwaitMakesItAStandby) {
  table.announced("slow", "cell");
  clock.advance(kWait + 1s);
  EXPECT_FALSE(look());
  table.claim(claim("slow", /*standby=*/false, 2));
  clock.advance(contract::kStartClaimAwait);
  EXPECT_FALSE(look());
}

TEST_F(VacancyTest, OfTwoStandbysOnlyTheOneThatStartedFirstTakesTheCell) {
  table.claim(claim("aa", /*standby=*/true, 0, 50));  // started before us
  clock.advance(kWait * 10);
  EXPECT_FALSE(look());
  PrimaryWatch senior{claim("aa", true, 0, 50), clock.now() - kWait * 10, kWait};
  EXPECT_TRUE(senior.look(view_of(table), clock.now())) << "the senior takes it";
  table.set_alive("aa", false);  // it died before it served
  EXPECT_TRUE(look()) << "then the next one does";
}

TEST_F(VacancyTest, OfTwoStandbysStartedAtOnceTheLowerParticipantTakesTheCell) {
  table.claim(claim("cc", /*standby=*/true, 0, 100));
  clock.advance(kWait);
  EXPECT_TRUE(look()) << "bb ranks before cc";
  PrimaryWatch other{claim("cc", true, 0, 100), clock.now() - kWait, kWait};
  EXPECT_FALSE(other.look(view_of(table), clock.now()));
}

TEST_F(PrimaryWatchTest, OnlyTheSeniorStandbyTakesOverFromALostPrimary) {
  table.claim(claim("00", /*standby=*/true, 0));  // same start, lower participant
  EXPECT_FALSE(look());
  table.set_alive("aa", false);
  EXPECT_FALSE(look());
  clock.advance(contract::kOwnerLapseConfirm);
  EXPECT_FALSE(look()) << "the senior standby takes over, not this one";
  table.forget("00");
  EXPECT_TRUE(look());
}

}  // namespace
}  // namespace dh3::dds
