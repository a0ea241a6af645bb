// dh3-service on a TCP transfer box served by a dh3-sim process, whose control
// channel injects what a real cell does: objects that slip out of the fingers,
// hands that stop answering. And several buses in one service.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "service_fixture.hpp"

namespace dh3::test {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

std::string box_config(const std::string& spec, const std::string& extra = {}) {
  return "buses:\n  - name: box\n    spec: " + spec +
         "\n    command_interval_ms: 2\n    poll_interval_moving_ms: 20\n"
         "    poll_interval_idle_ms: 50\n    reply_timeout_ms: 100\n" +
         extra + "    hands: [{id: 1}, {id: 2}, {id: 3}]\n";
}

class ServiceWithSimTest : public ::testing::Test {
 protected:
  void start(const std::string& extra = {}) {
    ASSERT_NE(sim_.port(), 0) << "dh3-sim did not start";
    config_ = std::make_unique<TempFile>(box_config(sim_.bus_spec(), extra));
    service_ =
        std::make_unique<ServiceProcess>(std::vector<std::string>{"--config", config_->path()});
    ASSERT_TRUE(service_->started());
    client_ = connected_client(service_->name());
    ASSERT_TRUE(client_);
    for (std::uint16_t id = 1; id <= 3; ++id) {
      ASSERT_TRUE(client_->wait_status(hand(id), [](const auto& s) { return s.online(); }))
          << "hand " << id << " never online";
    }
  }

  msg::HandAddress hand(std::uint16_t id) const {
    return DdsTestClient::hand(service_->name(), "box", id);
  }

  bool has_event(std::uint16_t id, msg::EventKind kind) {
    return client_
        ->wait_event(
            [&](const msg::HandEvent& e) { return e.hand().can_id() == id && e.kind() == kind; })
        .has_value();
  }

  SimProcess sim_{
      {"--hands", "1,2,3", "--object", "1:40", "--init-time-ms", "50", "--reply-delay-ms", "1"}};
  std::unique_ptr<TempFile> config_;
  std::unique_ptr<ServiceProcess> service_;
  std::unique_ptr<DdsTestClient> client_;
};

TEST_F(ServiceWithSimTest, GraspThenDropIsReportedAsEvents) {
  start();
  ASSERT_EQ(client_->call(hand(1), msg::INITIALIZE)->code(), msg::OK);
  const auto grasp = client_->call(hand(1), msg::GRASP, 40);
  ASSERT_TRUE(grasp);
  EXPECT_EQ(grasp->code(), msg::OK) << grasp->message();
  EXPECT_EQ(grasp->grasp(), msg::GRASPED);
  EXPECT_TRUE(has_event(1, msg::EVENT_GRASPED));

  EXPECT_THAT(sim_.control("drop 1"), StartsWith("ok"));
  EXPECT_TRUE(has_event(1, msg::EVENT_DROPPED));
  EXPECT_TRUE(
      client_->wait_status(hand(1), [](const auto& s) { return s.grip() == msg::GRIP_DROPPED; }));
  const auto dropped =
      client_->wait_event([](const auto& e) { return e.kind() == msg::EVENT_DROPPED; });
  ASSERT_TRUE(dropped);
  EXPECT_EQ(dropped->hand().service(), service_->name());
  EXPECT_EQ(dropped->hand().bus(), "box");

  // Without the object, the next grasp closes on nothing.
  const auto missed = client_->call(hand(1), msg::GRASP, 40);
  ASSERT_TRUE(missed);
  EXPECT_EQ(missed->grasp(), msg::MISSED);
  EXPECT_TRUE(has_event(1, msg::EVENT_MISSED));
}

TEST_F(ServiceWithSimTest, MutedHandTimesOutWhileTheOthersKeepAnswering) {
  start();
  EXPECT_THAT(sim_.control("mute 2"), StartsWith("ok"));
  // A long deadline for hand 2: its reply must not come before the others'.
  const auto stuck = client_->send(client_->request(hand(2), msg::READ_REGISTER, 0, 0x0602, 10000));
  for (int round = 0; round < 10; ++round) {
    for (const std::uint16_t id : {1, 3}) {
      const auto reply = client_->call(hand(id), msg::READ_REGISTER, 0, 0x0602);
      ASSERT_TRUE(reply);
      EXPECT_EQ(reply->code(), msg::OK) << reply->message();
    }
  }
  EXPECT_EQ(client_->reply_count(stuck), 0U) << "hand 2's request ended while the others ran";
  const auto timed_out = client_->wait_reply(stuck);
  ASSERT_TRUE(timed_out);
  EXPECT_EQ(timed_out->code(), msg::TIMEOUT);
  EXPECT_THAT(timed_out->message(), HasSubstr("hand 2"));
  EXPECT_TRUE(client_->wait_status(hand(2), [](const auto& s) { return !s.online(); }));
  EXPECT_TRUE(has_event(2, msg::EVENT_OFFLINE));

  EXPECT_THAT(sim_.control("unmute 2"), StartsWith("ok"));
  EXPECT_TRUE(client_->wait_status(hand(2), [](const auto& s) { return s.online(); }));
  EXPECT_TRUE(has_event(2, msg::EVENT_ONLINE));
  // Exactly one reply each: none of the requests gets a second one later.
  const auto duplicate = client_->wait_duplicate_reply(kDuplicateGrace);
  EXPECT_FALSE(duplicate) << client_->describe_replies(duplicate->second, duplicate->first);
}

TEST_F(ServiceWithSimTest, FullQueueAnswersBusy) {
  start("    queue_capacity: 1\n");
  EXPECT_THAT(sim_.control("mute 3"), StartsWith("ok"));
  std::vector<std::uint64_t> seqs;
  for (int i = 0; i < 6; ++i) {
    seqs.push_back(client_->send(client_->request(hand(3), msg::READ_REGISTER, 0, 0x0602, 3000)));
  }
  int busy = 0;
  for (const auto seq : seqs) {
    const auto reply = client_->wait_reply(seq);
    ASSERT_TRUE(reply) << "request " << seq;
    if (reply->code() == msg::BUSY) {
      ++busy;
      EXPECT_THAT(reply->message(), HasSubstr("hand 3"));
    }
  }
  EXPECT_GE(busy, 1);
  const auto duplicate = client_->wait_duplicate_reply(kDuplicateGrace);
  EXPECT_FALSE(duplicate) << client_->describe_replies(duplicate->second, duplicate->first);
}

TEST(ServiceDiscovery, HandsOfABusWithoutAListAreFoundAndServed) {
  SimProcess sim({"--hands", "3,9", "--init-time-ms", "50"});
  ASSERT_NE(sim.port(), 0);
  // No hands listed: the service probes the bus and serves what answers.
  ServiceProcess service({"--bus", "box=" + sim.bus_spec()});
  auto client = connected_client(service.name());
  ASSERT_TRUE(client);
  const auto info = client->wait_info(service.name(), [](const msg::ServiceInfo& i) {
    return i.buses().size() == 1 && i.buses()[0].hands().size() == 2;
  });
  ASSERT_TRUE(info);
  EXPECT_EQ(info->buses()[0].name(), "box");
  EXPECT_EQ(info->buses()[0].hands()[0].can_id(), 3);
  EXPECT_EQ(info->buses()[0].hands()[1].can_id(), 9);

  const auto nine = DdsTestClient::hand(service.name(), "box", 9);
  EXPECT_TRUE(client->wait_status(nine, [](const auto& s) { return s.online(); }));
  const auto init = client->call(nine, msg::INITIALIZE);
  ASSERT_TRUE(init);
  EXPECT_EQ(init->code(), msg::OK) << init->message();
  const auto scan = client->call(DdsTestClient::hand(service.name(), "box", 0), msg::SCAN);
  ASSERT_TRUE(scan);
  EXPECT_EQ(scan->code(), msg::OK) << scan->message();
  EXPECT_THAT(scan->found_ids(), ::testing::ElementsAre(3, 9));
  EXPECT_EQ(client->call(DdsTestClient::hand(service.name(), "box", 4), msg::MOVE, 10)->code(),
            msg::UNKNOWN_HAND);
}

TEST(ServiceTwoBuses, BothBusesServeTheirHandsAtOnce) {
  SimProcess sim({"--hands", "4", "--init-time-ms", "50"});
  ASSERT_NE(sim.port(), 0);
  TempFile config(R"(
buses:
  - name: local
    spec: sim:1,2
    sim: {reply_delay_ms: 1, init_time_ms: 50}
  - name: remote
    spec: )" + sim.bus_spec() +
                  R"(
    hands: [{id: 4, name: far}]
)");
  ServiceProcess service({"--config", config.path()});
  auto client = connected_client(service.name());
  ASSERT_TRUE(client);
  const auto info = client->wait_info(service.name(), [](const msg::ServiceInfo& i) {
    return i.buses().size() == 2 && i.buses()[0].link_up() && i.buses()[1].link_up();
  });
  ASSERT_TRUE(info);
  EXPECT_EQ(info->buses()[0].name(), "local");
  EXPECT_EQ(info->buses()[1].name(), "remote");
  EXPECT_EQ(info->buses()[1].spec(), sim.bus_spec());

  const auto local = DdsTestClient::hand(service.name(), "local", 2);
  const auto remote = DdsTestClient::hand(service.name(), "remote", 4);
  const auto init_local = client->send(client->request(local, msg::INITIALIZE));
  const auto init_remote = client->send(client->request(remote, msg::INITIALIZE));
  ASSERT_EQ(client->wait_reply(init_local)->code(), msg::OK);
  ASSERT_EQ(client->wait_reply(init_remote)->code(), msg::OK);
  EXPECT_EQ(client->call(local, msg::MOVE, 30)->code(), msg::OK);
  EXPECT_EQ(client->call(remote, msg::MOVE, 70)->code(), msg::OK);
  EXPECT_TRUE(client->wait_status(local, [](const auto& s) { return s.position() == 30; }));
  const auto far = client->wait_status(remote, [](const auto& s) { return s.position() == 70; });
  ASSERT_TRUE(far);
  EXPECT_EQ(far->name(), "far");
  // The same CAN ID on another bus is another hand.
  EXPECT_EQ(client->call(DdsTestClient::hand(service.name(), "remote", 2), msg::MOVE, 10)->code(),
            msg::UNKNOWN_HAND);
}

}  // namespace
}  // namespace dh3::test
