// PrimaryWatch: when a standby judges its active service lost, on a fake
// clock and the ownership rule's table.

#include <gtest/gtest.h>

#include "primary_watch.hpp"

namespace dh3::dds {
namespace {

using namespace std::chrono_literals;

contract::OwnerClaim claim(const std::string& participant, bool standby, std::uint64_t epoch) {
  contract::OwnerClaim made;
  made.participant = participant;
  made.service = "cell";
  made.host = "pc1";
  made.pid = 42;
  made.standby = standby;
  made.epoch = epoch;
  return made;
}

class PrimaryWatchTest : public ::testing::Test {
 protected:
  void SetUp() override {
    table.claim(claim("aa", /*standby=*/false, 3));
    table.set_alive("aa", true);
    table.claim(claim("bb", /*standby=*/true, 0));  // the standby itself
    table.set_alive("bb", true);
  }
  std::optional<PrimaryLapse> look() {
    return watch.look(table.owner("cell"), table.highest_epoch("cell"), clock.now());
  }

  FakeClock clock;
  contract::OwnerTable table;
  PrimaryWatch watch;
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
  EXPECT_EQ(lost->primary.participant, "aa");
  EXPECT_EQ(lost->since, lapsed);
  EXPECT_EQ(lost->epoch, 3u);  // the takeover claims above it
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
  EXPECT_FALSE(watch.look(table.owner("cell"), 3, clock.now(), &changed));
  EXPECT_TRUE(changed);
  EXPECT_FALSE(watch.look(table.owner("cell"), 3, clock.now(), &changed));
  EXPECT_FALSE(changed);
  table.claim(claim("cc", /*standby=*/false, 4));  // took the name over
  EXPECT_FALSE(watch.look(table.owner("cell"), 4, clock.now(), &changed));
  EXPECT_TRUE(changed);
  table.set_alive("cc", true);
  table.set_alive("cc", false);
  clock.advance(contract::kOwnerLapseConfirm);
  EXPECT_FALSE(look());  // "aa" still lives: it owns again
}

}  // namespace
}  // namespace dh3::dds
