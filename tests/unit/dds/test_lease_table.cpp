#include <gtest/gtest.h>

#include <chrono>

#include "lease_mirror.hpp"
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


// ---------------------------------------------------------------------------
// The hand-over to a standby: the active service's table writes each change
// as a lease sample (lease_sample), the standby keeps them per writer
// (LeaseMirror) and the service that takes over loads the primary's
// (LeaseTable::load). Two fake clocks: the PCs' clocks need not agree.

class LeaseHandoverTest : public ::testing::Test {
 protected:
  LeaseHandoverTest() {
    primary_.on_change([this](HandKey hand) {
      mirror_.received(kPrimary, lease_sample("cell", "left", hand.can_id, primary_.lease_of(hand)),
                       standby_clock_.now());
    });
  }
  /// What the standby hands the service at a takeover from the primary.
  [[nodiscard]] std::vector<HeldLease> handed_over() const {
    std::vector<HeldLease> held;
    for (const auto& lease : mirror_.held_by_writer(kPrimary, standby_clock_.now())) {
      EXPECT_EQ(lease.bus, "left");
      held.push_back({{0, lease.can_id}, lease.holder_id, lease.holder, lease.left});
    }
    return held;
  }

  static constexpr const char* kPrimary = "01.0f.aa.aa";
  static constexpr const char* kAlice = "01.0f.a1.1c";
  static constexpr const char* kBob = "01.0f.b0.b0";
  FakeClock primary_clock_;
  FakeClock standby_clock_{TimePoint{} + std::chrono::hours(7)};
  LeaseTable primary_{primary_clock_};
  LeaseMirror mirror_{"cell"};
  LeaseTable taken_over_{standby_clock_};  ///< the service the standby became
};

TEST_F(LeaseHandoverTest, ALeaseKeepsItsHolderAndTheTimeItHadLeft) {
  ASSERT_EQ(primary_.acquire(kHand, kAlice, milliseconds(10'000), "alice@pc").outcome,
            LeaseOutcome::granted);
  primary_clock_.advance(milliseconds(4000));
  standby_clock_.advance(milliseconds(4000));
  ASSERT_EQ(primary_.renew(kHand, kAlice, milliseconds(10'000)).outcome, LeaseOutcome::granted);
  // The primary dies 3 s after the renewal; the standby takes over.
  standby_clock_.advance(milliseconds(3000));
  taken_over_.load(handed_over());

  EXPECT_EQ(taken_over_.holder(kHand), "alice@pc");
  EXPECT_TRUE(taken_over_.held_by(kHand, kAlice));
  EXPECT_EQ(taken_over_.blocking_holder(kHand, kBob), "alice@pc");
  EXPECT_EQ(taken_over_.acquire(kHand, kBob, milliseconds(1000), "bob@pc").outcome,
            LeaseOutcome::held_by_other);
  EXPECT_FALSE(taken_over_.blocking_holder(kHand, kAlice));
  // 10 s from the renewal: 7 s from the takeover, not 10.
  EXPECT_EQ(taken_over_.next_expiry(), standby_clock_.now() + milliseconds(7000));
  standby_clock_.advance(milliseconds(6999));
  EXPECT_TRUE(taken_over_.expire().empty());
  standby_clock_.advance(milliseconds(1));
  const auto ended = taken_over_.expire();
  ASSERT_EQ(ended.size(), 1U);
  EXPECT_EQ(ended[0].holder_id, kAlice);
  EXPECT_EQ(taken_over_.holder(kHand), "");
}

TEST_F(LeaseHandoverTest, TheHolderRenewsUnderTheNewOwner) {
  primary_.acquire(kHand, kAlice, milliseconds(2000), "alice@pc");
  standby_clock_.advance(milliseconds(1500));
  taken_over_.load(handed_over());
  EXPECT_EQ(taken_over_.renew(kHand, kAlice, milliseconds(2000)).outcome, LeaseOutcome::granted);
  standby_clock_.advance(milliseconds(1900));
  EXPECT_TRUE(taken_over_.expire().empty());
  EXPECT_TRUE(taken_over_.held_by(kHand, kAlice));
  // By its participant id, also written as the service writes it.
  EXPECT_EQ(taken_over_.release(kHand, kBob).outcome, LeaseOutcome::held_by_other);
  EXPECT_EQ(taken_over_.release(kHand, kAlice).outcome, LeaseOutcome::granted);
  EXPECT_EQ(taken_over_.holder(kHand), "");
}

TEST_F(LeaseHandoverTest, LeasesThatEndedBeforeTheTakeoverAreNotHandedOver) {
  primary_.acquire(kHand, kAlice, milliseconds(5000), "alice@pc");
  primary_.acquire(kOtherHand, kBob, milliseconds(1000), "bob@pc");
  primary_.acquire(HandKey{0, 3}, kBob, milliseconds(5000), "bob@pc");
  ASSERT_EQ(primary_.release(kHand, kAlice).outcome, LeaseOutcome::granted);
  primary_clock_.advance(milliseconds(1000));
  ASSERT_EQ(primary_.expire().size(), 1U);  // kOtherHand's
  ASSERT_EQ(primary_.drop_client(kBob).size(), 1U);  // hand 3's: bob left the domain
  taken_over_.load(handed_over());
  EXPECT_TRUE(taken_over_.leases().empty());
  EXPECT_FALSE(taken_over_.next_expiry());
}

TEST_F(LeaseHandoverTest, ALeaseWhoseTimeRanOutAtTheStandbyIsNotHandedOver) {
  primary_.acquire(kHand, kAlice, milliseconds(1000), "alice@pc");
  // The primary died without a word; its expiry is the standby's to count.
  standby_clock_.advance(milliseconds(1000));
  taken_over_.load(handed_over());
  EXPECT_EQ(taken_over_.holder(kHand), "");
  EXPECT_EQ(taken_over_.acquire(kHand, kBob, milliseconds(1000), "bob@pc").outcome,
            LeaseOutcome::granted);
}

TEST_F(LeaseHandoverTest, OnlyTheLostOwnersSamplesAreHandedOver) {
  primary_.acquire(kHand, kAlice, milliseconds(5000), "alice@pc");
  // Another participant writes lease samples of its own: bob holding both hands.
  for (const HandKey hand : {kHand, kOtherHand}) {
    mirror_.received(kBob,
                     lease_sample("cell", "left", hand.can_id,
                                  HeldLease{hand, kBob, "bob@pc", milliseconds(60'000)}),
                     standby_clock_.now());
  }
  // And one of another cell, from the primary's participant.
  mirror_.received(kPrimary,
                   lease_sample("other-cell", "left", kOtherHand.can_id,
                                HeldLease{kOtherHand, kBob, "bob@pc", milliseconds(60'000)}),
                   standby_clock_.now());
  taken_over_.load(handed_over());
  EXPECT_TRUE(taken_over_.held_by(kHand, kAlice));
  EXPECT_FALSE(taken_over_.held_by(kHand, kBob));
  EXPECT_EQ(taken_over_.holder(kOtherHand), "");
  EXPECT_EQ(taken_over_.blocking_holder(kHand, kBob), "alice@pc");
}

TEST_F(LeaseHandoverTest, ALoadedLeaseIsToldAsAChange) {
  // The service that took over writes what it loaded: its own standby learns it.
  std::vector<HandKey> told;
  taken_over_.on_change([&told](HandKey hand) { told.push_back(hand); });
  primary_.acquire(kHand, kAlice, milliseconds(5000), "alice@pc");
  taken_over_.load(handed_over());
  EXPECT_EQ(told, std::vector<HandKey>{kHand});
}

}  // namespace
}  // namespace dh3::dds
