#include <gtest/gtest.h>

#include <chrono>

#include "lease_table.hpp"

namespace dh3::dds {
namespace {

using std::chrono::milliseconds;

constexpr HandKey kHand{0, 1};
constexpr HandKey kOtherHand{0, 2};
constexpr HandKey kOtherBus{1, 1};

class LeaseTableTest : public ::testing::Test {
 protected:
  FakeClock clock_;
  LeaseTable table_{clock_};
};

TEST_F(LeaseTableTest, FreeHandBlocksNobody) {
  EXPECT_FALSE(table_.blocking_holder(kHand, "alice"));
  EXPECT_EQ(table_.holder(kHand), "");
  EXPECT_FALSE(table_.next_expiry());
}

TEST_F(LeaseTableTest, HolderIsShownByItsNameAndKnownByItsId) {
  const auto answer = table_.acquire(kHand, "0a1b", milliseconds(1000), "dh3ctl@cell-pc");
  EXPECT_EQ(answer.holder, "dh3ctl@cell-pc");
  EXPECT_EQ(table_.holder(kHand), "dh3ctl@cell-pc");
  EXPECT_EQ(table_.blocking_holder(kHand, "dh3ctl@cell-pc"), "dh3ctl@cell-pc");  // a name is no id
  EXPECT_FALSE(table_.blocking_holder(kHand, "0a1b"));
  EXPECT_TRUE(table_.held_by(kHand, "0A.1B"));
  EXPECT_FALSE(table_.held_by(kHand, "dh3ctl@cell-pc"));
  EXPECT_FALSE(table_.held_by(kOtherHand, "0a1b"));
  // Another participant announcing the same name is still another client.
  const auto other = table_.acquire(kHand, "0c0d", milliseconds(1000), "dh3ctl@cell-pc");
  EXPECT_EQ(other.outcome, LeaseOutcome::held_by_other);
  EXPECT_EQ(table_.release(kHand, "0c0d").outcome, LeaseOutcome::held_by_other);
  EXPECT_EQ(table_.renew(kHand, "0c0d", milliseconds(1000)).outcome,
            LeaseOutcome::held_by_other);
  const auto ended = table_.drop_client("0a1b");
  ASSERT_EQ(ended.size(), 1U);
  EXPECT_EQ(ended[0].holder, "dh3ctl@cell-pc");
  EXPECT_EQ(ended[0].holder_id, "0a1b");
}

TEST_F(LeaseTableTest, HolderBlocksOthersButNotItself) {
  const auto answer = table_.acquire(kHand, "alice", milliseconds(1000));
  EXPECT_EQ(answer.outcome, LeaseOutcome::granted);
  EXPECT_TRUE(answer.holder_changed);
  EXPECT_EQ(answer.holder, "alice");
  EXPECT_EQ(table_.holder(kHand), "alice");
  EXPECT_FALSE(table_.blocking_holder(kHand, "alice"));
  EXPECT_EQ(table_.blocking_holder(kHand, "bob"), "alice");
  // Other hands, also on other buses, stay free.
  EXPECT_FALSE(table_.blocking_holder(kOtherHand, "bob"));
  EXPECT_FALSE(table_.blocking_holder(kOtherBus, "bob"));
}

TEST_F(LeaseTableTest, SecondClientIsRefusedAndToldTheHolder) {
  (void)table_.acquire(kHand, "alice", milliseconds(1000));
  const auto answer = table_.acquire(kHand, "bob", milliseconds(1000));
  EXPECT_EQ(answer.outcome, LeaseOutcome::held_by_other);
  EXPECT_EQ(answer.holder, "alice");
  EXPECT_FALSE(answer.holder_changed);
  EXPECT_EQ(table_.renew(kHand, "bob", milliseconds(1000)).outcome, LeaseOutcome::held_by_other);
  EXPECT_EQ(table_.release(kHand, "bob").outcome, LeaseOutcome::held_by_other);
  EXPECT_EQ(table_.holder(kHand), "alice");
}

TEST_F(LeaseTableTest, ReacquiringByTheHolderExtendsWithoutAChange) {
  (void)table_.acquire(kHand, "alice", milliseconds(1000));
  clock_.advance(milliseconds(900));
  const auto answer = table_.acquire(kHand, "alice", milliseconds(1000));
  EXPECT_EQ(answer.outcome, LeaseOutcome::granted);
  EXPECT_FALSE(answer.holder_changed);
  clock_.advance(milliseconds(900));
  EXPECT_EQ(table_.holder(kHand), "alice");
}

TEST_F(LeaseTableTest, LeaseRunsOutWithoutRenewal) {
  (void)table_.acquire(kHand, "alice", milliseconds(1000));
  EXPECT_EQ(table_.next_expiry(), clock_.now() + milliseconds(1000));
  clock_.advance(milliseconds(999));
  EXPECT_TRUE(table_.expire().empty());
  clock_.advance(milliseconds(1));
  // Expired leases block nobody even before the timer ends them.
  EXPECT_FALSE(table_.blocking_holder(kHand, "bob"));
  const auto ended = table_.expire();
  ASSERT_EQ(ended.size(), 1U);
  EXPECT_EQ(ended[0].hand, kHand);
  EXPECT_EQ(ended[0].holder, "alice");
  EXPECT_FALSE(table_.next_expiry());
}

TEST_F(LeaseTableTest, RenewalKeepsTheLease) {
  (void)table_.acquire(kHand, "alice", milliseconds(1000));
  clock_.advance(milliseconds(800));
  EXPECT_EQ(table_.renew(kHand, "alice", milliseconds(1000)).outcome, LeaseOutcome::granted);
  clock_.advance(milliseconds(800));
  EXPECT_TRUE(table_.expire().empty());
  EXPECT_EQ(table_.blocking_holder(kHand, "bob"), "alice");
}

TEST_F(LeaseTableTest, RenewingAnExpiredLeaseIsRefused) {
  (void)table_.acquire(kHand, "alice", milliseconds(1000));
  clock_.advance(milliseconds(1500));
  EXPECT_EQ(table_.renew(kHand, "alice", milliseconds(1000)).outcome, LeaseOutcome::not_held);
  EXPECT_EQ(table_.renew(kOtherHand, "alice", milliseconds(1000)).outcome, LeaseOutcome::not_held);
}

TEST_F(LeaseTableTest, AnotherClientMayTakeAnExpiredLease) {
  (void)table_.acquire(kHand, "alice", milliseconds(1000));
  clock_.advance(milliseconds(1000));
  const auto answer = table_.acquire(kHand, "bob", milliseconds(1000));
  EXPECT_EQ(answer.outcome, LeaseOutcome::granted);
  EXPECT_TRUE(answer.holder_changed);
  EXPECT_EQ(table_.blocking_holder(kHand, "alice"), "bob");
}

TEST_F(LeaseTableTest, ReleaseFreesTheHand) {
  (void)table_.acquire(kHand, "alice", milliseconds(1000));
  const auto answer = table_.release(kHand, "alice");
  EXPECT_EQ(answer.outcome, LeaseOutcome::granted);
  EXPECT_TRUE(answer.holder_changed);
  EXPECT_FALSE(table_.blocking_holder(kHand, "bob"));
  // Releasing again, or a lease never taken, is harmless.
  const auto again = table_.release(kHand, "alice");
  EXPECT_EQ(again.outcome, LeaseOutcome::granted);
  EXPECT_FALSE(again.holder_changed);
}

TEST_F(LeaseTableTest, ParticipantLeavingEndsAllItsLeases) {
  const std::string alice = "010f2a3b4c5d6e7f80918a9b";
  (void)table_.acquire(kHand, alice, milliseconds(60000));
  (void)table_.acquire(kOtherBus, alice, milliseconds(60000));
  (void)table_.acquire(kOtherHand, "bob", milliseconds(60000));
  // Fast DDS prints prefixes dotted and in either case: the same participant.
  const auto ended = table_.drop_client("01.0F.2A.3B.4C.5D.6E.7F.80.91.8A.9B");
  ASSERT_EQ(ended.size(), 2U);
  EXPECT_FALSE(table_.blocking_holder(kHand, "bob"));
  EXPECT_FALSE(table_.blocking_holder(kOtherBus, "bob"));
  EXPECT_EQ(table_.blocking_holder(kOtherHand, alice), "bob");
}

TEST_F(LeaseTableTest, UnrelatedParticipantLeavingEndsNothing) {
  (void)table_.acquire(kHand, "alice", milliseconds(60000));
  EXPECT_TRUE(table_.drop_client("ffffffffffffffffffffffff").empty());
  EXPECT_TRUE(table_.drop_client("").empty());
  EXPECT_EQ(table_.holder(kHand), "alice");
}

TEST_F(LeaseTableTest, BusWideCheckSeesAnyOtherHolderOnTheBus) {
  (void)table_.acquire(kOtherHand, "alice", milliseconds(1000));
  EXPECT_EQ(table_.blocking_holder_on_bus(0, "bob"), "alice");
  EXPECT_FALSE(table_.blocking_holder_on_bus(0, "alice"));
  EXPECT_FALSE(table_.blocking_holder_on_bus(1, "bob"));
}

TEST_F(LeaseTableTest, NextExpiryIsTheEarliest) {
  (void)table_.acquire(kHand, "alice", milliseconds(5000));
  (void)table_.acquire(kOtherHand, "bob", milliseconds(200));
  EXPECT_EQ(table_.next_expiry(), clock_.now() + milliseconds(200));
}

TEST(CanonicalClientId, DropsSeparatorsAndLowercases) {
  EXPECT_EQ(canonical_client_id("01.0F:Ab"), "010fab");
  EXPECT_EQ(canonical_client_id("robot-cell-7"), "robot-cell-7");
}

}  // namespace
}  // namespace dh3::dds
