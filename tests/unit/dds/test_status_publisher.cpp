// StatusPublisher's hand slots without DDS (no writers): what a reply carries
// of a hand's status, when a sample is prepared anew, and the refresh rule.

#include <gtest/gtest.h>

#include <chrono>

#include "dh3/hand/hand_roster.hpp"
#include "hand_directory.hpp"
#include "lease_table.hpp"
#include "status_publisher.hpp"

namespace dh3::dds {
namespace {

using namespace std::chrono_literals;

constexpr HandKey kHand{0, 1};

class StatusPublisherTest : public ::testing::Test {
 protected:
  StatusPublisherTest() {
    options_.status_refresh = 5s;
    directory_.add_bus("bus0", roster_);
    publisher_.add_bus("bus0", "sim:1", {1});
  }

  static hand::HandState state(std::int32_t position, bool online = true) {
    hand::HandState state;
    state.can_id = kHand.can_id;
    state.online = online;
    state.position = position;
    return state;
  }
  /// The status a reply about the hand carries now.
  msg::HandStatus carried() {
    msg::CommandReply reply;
    publisher_.attach_to(reply, kHand.bus, kHand.can_id);
    return reply.status();
  }

  ServiceOptions options_;
  FakeClock clock_;
  LeaseTable leases_{clock_};
  hand::HandRoster roster_{std::vector<hand::HandConfig>{{1, "left"}}};
  HandDirectory directory_;
  StatusPublisher publisher_{options_, clock_, leases_, directory_};
};

TEST_F(StatusPublisherTest, NoStatusBeforeTheFirstState) {
  EXPECT_EQ(carried().update_seq(), 0u);
  msg::CommandReply reply;
  publisher_.hold_republished(kHand, reply);
  EXPECT_EQ(reply.status().update_seq(), 0u);
}

TEST_F(StatusPublisherTest, ReplyCarriesTheHeldStateAndSendingKeepsIt) {
  publisher_.on_state(kHand.bus, state(100));
  EXPECT_EQ(carried().update_seq(), 1u);
  EXPECT_EQ(carried().position(), 100);
  EXPECT_EQ(carried().bus(), "bus0");
  publisher_.send_held(kHand.bus, kHand.can_id);
  EXPECT_EQ(carried().update_seq(), 1u);  // sent as prepared
  publisher_.on_state(kHand.bus, state(200));
  EXPECT_EQ(carried().update_seq(), 2u);
  EXPECT_EQ(carried().position(), 200);
}

TEST_F(StatusPublisherTest, FreshReadIsRepublishedOncePerRefresh) {
  publisher_.on_state(kHand.bus, state(100));
  publisher_.send_held(kHand.bus, kHand.can_id);
  clock_.advance(1s);
  publisher_.on_fresh(kHand.bus, state(100));
  EXPECT_EQ(carried().update_seq(), 1u);
  clock_.advance(5s);
  publisher_.on_fresh(kHand.bus, state(100));
  EXPECT_EQ(carried().update_seq(), 2u);
}

TEST_F(StatusPublisherTest, ALeasesSampleDoesNotPutTheNextFreshReadOff) {
  publisher_.on_state(kHand.bus, state(100));
  publisher_.send_held(kHand.bus, kHand.can_id);
  clock_.advance(4s);
  // Sent again for a lease: the values and their read time are 4 s old.
  leases_.acquire(kHand, "alice", 60s);
  publisher_.republish(kHand);
  EXPECT_EQ(carried().update_seq(), 2u);
  clock_.advance(2s);
  // The read time a watcher has is 6 s old now: the fresh read goes out.
  publisher_.on_fresh(kHand.bus, state(100));
  EXPECT_EQ(carried().update_seq(), 3u);
}

TEST_F(StatusPublisherTest, FreshReadOfAHeldSampleIsPreparedAgain) {
  publisher_.on_state(kHand.bus, state(100));  // held, not sent
  publisher_.on_fresh(kHand.bus, state(100));
  EXPECT_EQ(carried().update_seq(), 2u);
}

TEST_F(StatusPublisherTest, LeaseChangeHoldsASampleNamingTheHolder) {
  publisher_.on_state(kHand.bus, state(100));
  publisher_.send_held(kHand.bus, kHand.can_id);
  leases_.acquire(kHand, "alice", 1s);
  msg::CommandReply reply;
  publisher_.hold_republished(kHand, reply);
  EXPECT_EQ(reply.status().update_seq(), 2u);
  EXPECT_EQ(reply.status().lease_holder(), "alice");
  leases_.release(kHand, "alice");
  publisher_.republish(kHand);
  EXPECT_EQ(carried().update_seq(), 3u);
  EXPECT_EQ(carried().lease_holder(), "");
}

TEST_F(StatusPublisherTest, FirstPublicationSkipsHandsAlreadyPublished) {
  publisher_.publish_first(kHand.bus, {state(100)});
  EXPECT_EQ(carried().update_seq(), 1u);
  publisher_.publish_first(kHand.bus, {state(300)});
  EXPECT_EQ(carried().update_seq(), 1u);
  EXPECT_EQ(carried().position(), 100);
}

TEST_F(StatusPublisherTest, StopPublishesOnlineHandsOffline) {
  publisher_.on_state(kHand.bus, state(100));
  publisher_.publish_all_offline();
  EXPECT_FALSE(carried().online());
  EXPECT_EQ(carried().update_seq(), 2u);
  publisher_.publish_all_offline();  // already offline: nothing new
  EXPECT_EQ(carried().update_seq(), 2u);
}

}  // namespace
}  // namespace dh3::dds
