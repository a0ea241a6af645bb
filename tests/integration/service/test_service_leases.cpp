// Control leases between two clients (two DDS participants), through the
// running service: the holder alone moves the hand, everyone reads, the lease
// ends on release, on expiry and when the holder's participant leaves, and it
// belongs to that participant whatever client_id another one writes. The
// holder is shown by its participant's name ("alice"), never by its id.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "service_fixture.hpp"

namespace dh3::test {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

constexpr const char* kConfig = R"(
buses:
  - name: bus0
    spec: sim
    command_interval_ms: 2
    sim: {reply_delay_ms: 1, init_time_ms: 50}
    hands: [{id: 1}, {id: 2}]
)";

class ServiceLeasesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(service_.started());
    alice_ = connected_client(service_.name(), "alice");
    bob_ = connected_client(service_.name(), "bob");
    ASSERT_TRUE(alice_ && bob_);
    ASSERT_NE(alice_->client_id(), bob_->client_id());
    ASSERT_EQ(alice_->call(hand(1), msg::INITIALIZE)->code(), msg::OK);
  }

  msg::HandAddress hand(std::uint16_t id) const {
    return DdsTestClient::hand(service_.name(), "bus0", id);
  }

  static msg::ResultCode code(DdsTestClient& client, const msg::HandAddress& h,
                              msg::CommandType command, std::int32_t value = 0,
                              std::uint16_t reg = 0) {
    const auto reply = client.call(h, command, value, reg);
    return reply ? reply->code() : static_cast<msg::ResultCode>(99);  // no reply
  }

  bool status_shows_holder(DdsTestClient& client, const std::string& holder) {
    return client.wait_status(hand(1), [&](const auto& s) { return s.lease_holder() == holder; })
        .has_value();
  }

  TempFile config_{kConfig};
  ServiceProcess service_{{"--config", config_.path()}};
  std::unique_ptr<DdsTestClient> alice_;
  std::unique_ptr<DdsTestClient> bob_;
};

TEST_F(ServiceLeasesTest, HolderAloneMovesOthersStillRead) {
  const auto lease = alice_->call(hand(1), msg::ACQUIRE_LEASE, 60000);
  ASSERT_TRUE(lease);
  EXPECT_EQ(lease->code(), msg::OK) << lease->message();
  EXPECT_EQ(lease->lease_holder(), "alice");
  EXPECT_TRUE(status_shows_holder(*bob_, "alice"));

  const auto denied = bob_->call(hand(1), msg::MOVE, 50);
  ASSERT_TRUE(denied);
  EXPECT_EQ(denied->code(), msg::DENIED);
  EXPECT_EQ(denied->lease_holder(), "alice");
  EXPECT_THAT(denied->message(), HasSubstr("'alice'"));
  EXPECT_THAT(denied->message(), Not(HasSubstr(alice_->client_id())));
  for (const auto command : {msg::INITIALIZE, msg::GRASP, msg::RELEASE, msg::ROTATE,
                             msg::SET_CLOSING_FORCE, msg::STOP, msg::ENABLE_INIT_FEEDBACK}) {
    const std::int32_t value = command == msg::SET_CLOSING_FORCE || command == msg::GRASP ? 50 : 0;
    EXPECT_EQ(code(*bob_, hand(1), command, value), msg::DENIED) << command;
  }
  EXPECT_EQ(code(*bob_, hand(1), msg::ACQUIRE_LEASE, 1000), msg::DENIED);
  EXPECT_EQ(code(*bob_, hand(1), msg::RELEASE_LEASE), msg::DENIED);
  // Reads, scans and other hands stay open.
  EXPECT_EQ(code(*bob_, hand(1), msg::READ_REGISTER, 0, 0x0602), msg::OK);
  EXPECT_EQ(code(*bob_, hand(0), msg::SCAN), msg::OK);
  EXPECT_EQ(code(*bob_, hand(2), msg::INITIALIZE), msg::OK);
  // The holder moves as before.
  EXPECT_EQ(code(*alice_, hand(1), msg::MOVE, 50), msg::OK);
  EXPECT_EQ(code(*alice_, hand(1), msg::RENEW_LEASE, 60000), msg::OK);

  EXPECT_EQ(code(*alice_, hand(1), msg::RELEASE_LEASE), msg::OK);
  EXPECT_TRUE(status_shows_holder(*bob_, ""));
  EXPECT_EQ(code(*bob_, hand(1), msg::MOVE, 60), msg::OK);
  // Renewing a lease one does not hold is refused.
  EXPECT_EQ(code(*alice_, hand(1), msg::RENEW_LEASE, 1000), msg::DENIED);
}

TEST_F(ServiceLeasesTest, WithoutALeaseTheLastCommandWins) {
  EXPECT_EQ(code(*alice_, hand(1), msg::MOVE, 20), msg::OK);
  EXPECT_EQ(code(*bob_, hand(1), msg::MOVE, 80), msg::OK);
  EXPECT_TRUE(alice_->wait_status(
      hand(1), [](const auto& s) { return s.target_position() == 80 && s.position() == 80; }));
}

TEST_F(ServiceLeasesTest, LeaseExpiresWithoutRenewal) {
  ASSERT_EQ(code(*alice_, hand(1), msg::ACQUIRE_LEASE, 300), msg::OK);
  EXPECT_TRUE(status_shows_holder(*bob_, "alice"));
  // The service's timer ends it; the status says so.
  EXPECT_TRUE(status_shows_holder(*bob_, ""));
  EXPECT_EQ(code(*bob_, hand(1), msg::MOVE, 30), msg::OK);
  EXPECT_EQ(code(*alice_, hand(1), msg::RENEW_LEASE, 1000), msg::DENIED);
}

TEST_F(ServiceLeasesTest, LeaseEndsWhenTheHoldersParticipantLeaves) {
  ASSERT_EQ(code(*alice_, hand(1), msg::ACQUIRE_LEASE, 600000), msg::OK);
  EXPECT_TRUE(status_shows_holder(*bob_, "alice"));
  EXPECT_EQ(code(*bob_, hand(1), msg::MOVE, 30), msg::DENIED);
  alice_.reset();  // the participant leaves the domain
  EXPECT_TRUE(status_shows_holder(*bob_, ""));
  EXPECT_EQ(code(*bob_, hand(1), msg::MOVE, 30), msg::OK);
}

// Bob writes alice's client_id into his requests (it was published as the
// holder once): his participant is not alice's, so every one is DENIED, says
// why, and the hand keeps alice's target.
TEST_F(ServiceLeasesTest, ForgedClientIdOfTheHolderIsDeniedAndTheHandDoesNotMove) {
  ASSERT_EQ(code(*alice_, hand(1), msg::ACQUIRE_LEASE, 60000), msg::OK);
  ASSERT_EQ(code(*alice_, hand(1), msg::MOVE, 20), msg::OK);
  ASSERT_TRUE(bob_->wait_status(hand(1), [](const auto& s) { return s.target_position() == 20; }));
  std::uint64_t seq = 1000;  // beyond alice's own numbers: her replies are not these
  for (const auto command : {msg::MOVE, msg::RENEW_LEASE, msg::RELEASE_LEASE, msg::ACQUIRE_LEASE}) {
    auto forged = bob_->request(hand(1), command, command == msg::MOVE ? 30 : 60000);
    forged.client_id(alice_->client_id());
    forged.request_seq(++seq);
    bob_->send(forged, true);
    const auto reply = bob_->wait_reply(seq, kDdsDeadline, alice_->client_id());
    ASSERT_TRUE(reply) << command;
    EXPECT_EQ(reply->code(), msg::DENIED) << command;
    EXPECT_THAT(reply->message(), HasSubstr("a lease belongs to the participant that took it"))
        << command;
    EXPECT_EQ(reply->lease_holder(), "alice") << command;
  }
  // A read after the forged MOVE leaves the hand's queue after it would have:
  // its status still has alice's target, and alice still holds the lease.
  const auto read = bob_->call(hand(1), msg::READ_REGISTER, 0, 0x0602);
  ASSERT_TRUE(read);
  EXPECT_EQ(read->status().target_position(), 20);
  EXPECT_EQ(read->status().lease_holder(), "alice");
  EXPECT_EQ(code(*alice_, hand(1), msg::RENEW_LEASE, 60000), msg::OK);
}

}  // namespace
}  // namespace dh3::test
