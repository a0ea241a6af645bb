// Every command through DDS to dh3-service on its in-process simulator, as a
// user's program would send them: replies, status and events.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "service_fixture.hpp"

namespace dh3::test {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

constexpr const char* kSimConfig = R"(
buses:
  - name: bus0
    spec: sim
    command_interval_ms: 2
    poll_interval_moving_ms: 20
    poll_interval_idle_ms: 100
    sim: {reply_delay_ms: 1, init_time_ms: 100}
    hands:
      - {id: 1, name: left}
      - {id: 2, name: right, object: 40}
      - {id: 3}
)";

class ServiceCommandsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(service_.started());
    client_ = connected_client(service_.name());
    ASSERT_TRUE(client_) << "dh3-service did not answer on domain " << test_domain();
  }

  msg::HandAddress hand(std::uint16_t id) const {
    return DdsTestClient::hand(service_.name(), "bus0", id);
  }

  /// Sends a command and expects OK; returns the reply.
  msg::CommandReply ok(std::uint16_t id, msg::CommandType command, std::int32_t value = 0,
                       std::uint16_t reg = 0) {
    auto reply = client_->call(hand(id), command, value, reg);
    EXPECT_TRUE(reply) << "no reply";
    if (!reply) return {};
    EXPECT_EQ(reply->code(), msg::OK) << reply->message();
    return *reply;
  }

  bool has_event(std::uint16_t id, msg::EventKind kind) {
    return client_
        ->wait_event([&](const msg::HandEvent& e) {
          return e.hand().service() == service_.name() && e.hand().can_id() == id &&
                 e.kind() == kind;
        })
        .has_value();
  }

  TempFile config_{kSimConfig};
  ServiceProcess service_{{"--config", config_.path()}};
  std::unique_ptr<DdsTestClient> client_;
};

TEST_F(ServiceCommandsTest, PublishesItsInfoAndEveryHand) {
  const auto info = client_->wait_info(service_.name(), [](const msg::ServiceInfo& i) {
    return i.buses().size() == 1 && i.buses()[0].link_up();
  });
  ASSERT_TRUE(info);
  EXPECT_FALSE(info->version().empty());
  EXPECT_FALSE(info->host().empty());
  EXPECT_FALSE(info->admin_allowed());
  EXPECT_GT(info->started_ns(), 0U);
  const auto& bus = info->buses()[0];
  EXPECT_EQ(bus.name(), "bus0");
  EXPECT_EQ(bus.spec(), "sim:1,2,3");
  ASSERT_EQ(bus.hands().size(), 3U);
  EXPECT_EQ(bus.hands()[0].can_id(), 1);
  EXPECT_EQ(bus.hands()[0].name(), "left");
  EXPECT_EQ(bus.hands()[1].name(), "right");

  for (std::uint16_t id = 1; id <= 3; ++id) {
    const auto status =
        client_->wait_status(hand(id), [](const msg::HandStatus& s) { return s.online(); });
    ASSERT_TRUE(status) << "hand " << id << " never online";
    EXPECT_FALSE(status->initialized());
    EXPECT_EQ(status->lease_holder(), "");
  }
  EXPECT_EQ(client_->wait_status(hand(1), [](const auto&) { return true; })->name(), "left");
}

TEST_F(ServiceCommandsTest, MotionNeedsInitializationFirst) {
  const auto refused = client_->call(hand(3), msg::MOVE, 50);
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->code(), msg::NOT_INITIALIZED);
  EXPECT_THAT(refused->message(), HasSubstr("INITIALIZE"));

  ok(3, msg::INITIALIZE);
  EXPECT_TRUE(client_->wait_status(hand(3), [](const auto& s) { return s.initialized(); }));
  EXPECT_TRUE(has_event(3, msg::EVENT_INITIALIZED));

  const auto moved = ok(3, msg::MOVE, 60);
  EXPECT_EQ(moved.command(), msg::MOVE);
  EXPECT_EQ(moved.hand().can_id(), 3);
  EXPECT_EQ(moved.client_id(), client_->client_id());
  EXPECT_TRUE(client_->wait_status(hand(3), [](const msg::HandStatus& s) {
    return s.position() == 60 && s.target_position() == 60 && s.grip() == msg::GRIP_ARRIVED;
  }));
  EXPECT_TRUE(has_event(3, msg::EVENT_ARRIVED));
}

TEST_F(ServiceCommandsTest, ForcesRotationAndRegisters) {
  ok(1, msg::INITIALIZE);
  ok(1, msg::SET_CLOSING_FORCE, 30);
  ok(1, msg::SET_OPENING_FORCE, 70);
  EXPECT_EQ(ok(1, msg::READ_REGISTER, 0, 0x0502).value(), 30);
  EXPECT_EQ(ok(1, msg::READ_REGISTER, 0, 0x0503).value(), 70);
  EXPECT_EQ(ok(1, msg::READ_REGISTER, 0, 0x1301).value(), 0x04010200);
  ok(1, msg::ENABLE_INIT_FEEDBACK);
  EXPECT_EQ(ok(1, msg::READ_REGISTER, 0, 0x0801).value(), 0xA5);
  EXPECT_EQ(ok(1, msg::READ_REGISTER, 0, 0x0802).value(), 1);  // initialization finished

  ok(1, msg::ROTATE, 50);
  EXPECT_TRUE(client_->wait_status(hand(1), [](const msg::HandStatus& s) {
    return s.rotation() == 50 && s.rotation_state() == msg::ROTATION_ARRIVED;
  }));
  EXPECT_TRUE(has_event(1, msg::EVENT_ROTATION_ARRIVED));
  EXPECT_TRUE(client_->wait_status(hand(1), [](const msg::HandStatus& s) {
    return s.closing_force() == 30 && s.opening_force() == 70;
  }));
}

TEST_F(ServiceCommandsTest, GraspCatchesTheObjectAndMissesWithoutOne) {
  ok(1, msg::INITIALIZE);
  ok(2, msg::INITIALIZE);

  const auto caught = ok(2, msg::GRASP, 30);
  EXPECT_EQ(caught.grasp(), msg::GRASPED);
  EXPECT_EQ(caught.value(), 40);  // the object's position
  EXPECT_TRUE(has_event(2, msg::EVENT_GRASPED));
  EXPECT_TRUE(
      client_->wait_status(hand(2), [](const auto& s) { return s.grip() == msg::GRIP_GRASPED; }));

  const auto missed = ok(1, msg::GRASP, 30);
  EXPECT_EQ(missed.grasp(), msg::MISSED);
  EXPECT_TRUE(has_event(1, msg::EVENT_MISSED));
  EXPECT_TRUE(
      client_->wait_status(hand(1), [](const auto& s) { return s.grip() == msg::GRIP_MISSED; }));

  ok(2, msg::RELEASE, 100);
  EXPECT_TRUE(client_->wait_status(hand(2), [](const msg::HandStatus& s) {
    return s.position() == 100 && s.grip() == msg::GRIP_ARRIVED;
  }));
}

TEST_F(ServiceCommandsTest, ScanFindsEveryHand) {
  const auto reply = ok(0, msg::SCAN);
  EXPECT_THAT(reply.found_ids(), ElementsAre(1, 2, 3));
}

TEST_F(ServiceCommandsTest, StopIsAnsweredAndHoldsTheHand) {
  ok(1, msg::INITIALIZE);
  ok(1, msg::STOP);
  EXPECT_TRUE(client_->wait_status(hand(1), [](const auto& s) { return s.initialized(); }));
}

TEST_F(ServiceCommandsTest, AReplyCarriesTheStatusSampleThatFollowsIt) {
  const auto initialized = ok(1, msg::INITIALIZE);
  EXPECT_TRUE(initialized.status().initialized());
  const auto forced = ok(1, msg::SET_CLOSING_FORCE, 30);
  const msg::HandStatus& carried = forced.status();
  EXPECT_EQ(carried.service(), service_.name());
  EXPECT_EQ(carried.bus(), "bus0");
  EXPECT_EQ(carried.can_id(), 1);
  EXPECT_EQ(carried.name(), "left");
  EXPECT_EQ(carried.closing_force(), 30);
  EXPECT_GT(carried.update_seq(), initialized.status().update_seq());
  // The service writes the same sample (same update_seq, time and values) on
  // the status topic after the reply.
  ASSERT_TRUE(client_->wait_status(
      hand(1), [&](const auto& s) { return s.update_seq() >= carried.update_seq(); }));
  std::optional<msg::HandStatus> published;
  for (const auto& s : client_->status_history(hand(1))) {
    if (s.update_seq() == carried.update_seq()) published = s;
  }
  ASSERT_TRUE(published) << "no status sample with update_seq " << carried.update_seq();
  EXPECT_EQ(*published, carried);
  // A command that changes nothing carries the current status.
  const auto read = ok(1, msg::READ_REGISTER, 0, 0x0502);
  EXPECT_EQ(read.status().closing_force(), 30);
  EXPECT_GE(read.status().update_seq(), carried.update_seq());
}

TEST_F(ServiceCommandsTest, RepliesNotAboutOneHandCarryNoStatus) {
  EXPECT_EQ(ok(0, msg::SCAN).status().update_seq(), 0U);
  const auto unknown = client_->call(hand(9), msg::READ_REGISTER, 0, 0x0602);
  ASSERT_TRUE(unknown);
  EXPECT_EQ(unknown->code(), msg::UNKNOWN_HAND);
  EXPECT_EQ(unknown->status().update_seq(), 0U);
}

TEST_F(ServiceCommandsTest, ALeaseReplyCarriesTheStatusNamingTheNewHolder) {
  const auto lease = ok(2, msg::ACQUIRE_LEASE, 60000);
  EXPECT_EQ(lease.status().lease_holder(), "dh3-test");  // the participant's name
  EXPECT_EQ(lease.status().can_id(), 2);
  const auto released = ok(2, msg::RELEASE_LEASE);
  EXPECT_EQ(released.status().lease_holder(), "");
  EXPECT_GT(released.status().update_seq(), lease.status().update_seq());
}

TEST_F(ServiceCommandsTest, EveryRequestGetsExactlyOneReply) {
  ok(1, msg::INITIALIZE);
  std::vector<std::uint64_t> seqs;
  for (int i = 0; i < 20; ++i) {
    seqs.push_back(client_->send(client_->request(hand(1 + i % 3), msg::READ_REGISTER, 0, 0x0602)));
    seqs.push_back(client_->send(client_->request(hand(1), msg::MOVE, 200)));  // invalid
  }
  for (const auto seq : seqs) ASSERT_TRUE(client_->wait_reply(seq)) << "request " << seq;
  // A last round trip: anything duplicated would have arrived before its reply.
  ok(1, msg::READ_REGISTER, 0, 0x0602);
  for (const auto seq : seqs) EXPECT_EQ(client_->reply_count(seq), 1U) << "request " << seq;
}

}  // namespace
}  // namespace dh3::test
