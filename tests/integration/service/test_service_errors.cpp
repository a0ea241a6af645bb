// Every result code a client can get from dh3-service, each with a message that
// says why, and the routing rules: other services' requests are not answered.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "service_fixture.hpp"

namespace dh3::test {
namespace {

using ::testing::HasSubstr;

// Hand 1 moves slowly (10 s for the full stroke), so a motion is still running
// when the next command arrives. Hand 2's initialization never finishes in time.
constexpr const char* kConfig = R"(
buses:
  - name: slow
    spec: sim
    command_interval_ms: 2
    poll_interval_moving_ms: 20
    poll_interval_idle_ms: 100
    sim: {reply_delay_ms: 1, init_time_ms: 50, position_speed: 10}
    hands: [{id: 1}]
  - name: stuck
    spec: sim
    init_timeout_ms: 300
    sim: {reply_delay_ms: 1, init_time_ms: 60000}
    hands: [{id: 2}]
)";

class ServiceErrorsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(service_.started());
    client_ = connected_client(service_.name());
    ASSERT_TRUE(client_);
  }

  msg::HandAddress hand(const std::string& bus, std::uint16_t id) const {
    return DdsTestClient::hand(service_.name(), bus, id);
  }

  void expect_code(const msg::CommandRequest& request, msg::ResultCode code, const char* text) {
    const auto seq = client_->send(request);
    const auto reply = client_->wait_reply(seq, kDdsDeadline, request.client_id());
    ASSERT_TRUE(reply) << "no reply for " << request.command();
    EXPECT_EQ(reply->code(), code) << reply->message();
    EXPECT_THAT(reply->message(), HasSubstr(text));
    EXPECT_EQ(reply->request_seq(), seq);
    EXPECT_EQ(reply->client_id(), request.client_id());
    EXPECT_EQ(reply->command(), request.command());
  }

  TempFile config_{kConfig};
  ServiceProcess service_{{"--config", config_.path()}};
  std::unique_ptr<DdsTestClient> client_;
};

TEST_F(ServiceErrorsTest, OutOfRangeAndMalformedRequestsAreInvalid) {
  const auto h = hand("slow", 1);
  expect_code(client_->request(h, msg::MOVE, 101), msg::INVALID_ARGUMENT, "0-100");
  expect_code(client_->request(h, msg::RELEASE, -1), msg::INVALID_ARGUMENT, "0-100");
  expect_code(client_->request(h, msg::ROTATE, 101), msg::INVALID_ARGUMENT, "rotation");
  expect_code(client_->request(h, msg::GRASP, 19), msg::INVALID_ARGUMENT, "20-100");
  expect_code(client_->request(h, msg::SET_CLOSING_FORCE, 101), msg::INVALID_ARGUMENT, "force");
  expect_code(client_->request(h, msg::SET_OPENING_FORCE, 0), msg::INVALID_ARGUMENT, "force");
  expect_code(client_->request(h, msg::SET_CAN_ID, 256), msg::INVALID_ARGUMENT, "1-255");
  expect_code(client_->request(h, msg::SET_BAUD_RATE, 6), msg::INVALID_ARGUMENT, "0-5");
  expect_code(client_->request(h, msg::ACQUIRE_LEASE, 5), msg::INVALID_ARGUMENT, "lease");
  expect_code(client_->request(h, msg::READ_REGISTER, 0, 0x0999), msg::INVALID_ARGUMENT, "0x0999");
  expect_code(client_->request(h, static_cast<msg::CommandType>(77)), msg::INVALID_ARGUMENT,
              "unknown command 77");
  expect_code(client_->request(h, msg::MOVE, 50, 0, 60001), msg::INVALID_ARGUMENT, "timeout_ms");
  expect_code(client_->request(hand("slow", 0), msg::MOVE, 50), msg::INVALID_ARGUMENT, "can_id 0");
  expect_code(client_->request(hand("slow", 256), msg::MOVE, 50), msg::INVALID_ARGUMENT,
              "can_id 256");
  expect_code(client_->request(hand("", 1), msg::MOVE, 50), msg::INVALID_ARGUMENT, "bus");
  auto anonymous = client_->request(h, msg::MOVE, 50);
  anonymous.client_id("");
  expect_code(anonymous, msg::INVALID_ARGUMENT, "client_id");
  auto chatty = client_->request(h, msg::MOVE, 50);
  chatty.client_id(std::string(65, 'c'));
  expect_code(chatty, msg::INVALID_ARGUMENT, "client_id");
  // Nothing invalid moved the hand: it is still where it started.
  EXPECT_EQ(client_->call(h, msg::READ_REGISTER, 0, 0x0802)->value(), 0);  // not initialized
}

TEST_F(ServiceErrorsTest, UnknownBusOrHand) {
  expect_code(client_->request(hand("nope", 1), msg::MOVE, 50), msg::UNKNOWN_HAND, "slow, stuck");
  expect_code(client_->request(hand("slow", 9), msg::READ_REGISTER, 0, 0x0602), msg::UNKNOWN_HAND,
              "no hand 9");
  expect_code(client_->request(hand("nope", 0), msg::SCAN), msg::UNKNOWN_HAND, "nope");
}

TEST_F(ServiceErrorsTest, AdministrativeCommandsAreDeniedUnlessAllowed) {
  expect_code(client_->request(hand("slow", 1), msg::SET_CAN_ID, 5), msg::DENIED, "--allow-admin");
  expect_code(client_->request(hand("slow", 1), msg::SET_BAUD_RATE, 2), msg::DENIED,
              "administrative");
}

TEST_F(ServiceErrorsTest, EmptyServiceIsInvalidAndOtherServicesAreIgnored) {
  auto other = client_->request(hand("slow", 1), msg::READ_REGISTER, 0, 0x0602);
  other.hand().service("someone-else");
  const auto ignored = client_->send(other);
  auto empty = client_->request(hand("slow", 1), msg::READ_REGISTER, 0, 0x0602);
  empty.hand().service("");
  const auto answered = client_->send(empty);
  const auto reply = client_->wait_reply(answered);
  ASSERT_TRUE(reply);
  EXPECT_EQ(reply->code(), msg::INVALID_ARGUMENT);
  EXPECT_THAT(reply->message(), HasSubstr("service"));
  // One listener answers requests in order: had the other service's request
  // been answered, that reply would have come first.
  EXPECT_EQ(client_->reply_count(ignored), 0U);
}

TEST_F(ServiceErrorsTest, ARequestWrittenToAnotherIncarnationIsNotServed) {
  // As a client writes to the owner it believes, one that has since died;
  // the service that took over must not carry it out.
  const auto h = hand("slow", 1);
  ASSERT_TRUE(client_->call(h, msg::READ_REGISTER, 0, 0x0602));  // unaddressed: served
  const std::string service_id = client_->last_replier();
  const auto elsewhere = client_->send_to(client_->request(h, msg::READ_REGISTER, 0, 0x0602),
                                          "0123456789abcdef01234567");
  const auto reply = client_->wait_reply(
      client_->send_to(client_->request(h, msg::READ_REGISTER, 0, 0x0602), service_id));
  ASSERT_TRUE(reply) << "a request written to this service went unanswered";
  EXPECT_EQ(reply->code(), msg::OK) << reply->message();
  // Answered in order: the other incarnation's request would have come first.
  EXPECT_EQ(client_->reply_count(elsewhere), 0U);
}

TEST_F(ServiceErrorsTest, InitializationThatNeverFinishesFails) {
  const auto reply = client_->call(hand("stuck", 2), msg::INITIALIZE);
  ASSERT_TRUE(reply);
  EXPECT_EQ(reply->code(), msg::FAILED) << reply->message();
  EXPECT_FALSE(reply->message().empty());
}

TEST_F(ServiceErrorsTest, StopCancelsARunningGrasp) {
  const auto h = hand("slow", 1);
  ASSERT_EQ(client_->call(h, msg::INITIALIZE)->code(), msg::OK);
  // Closing from fully open takes 10 s here: the grasp is still running.
  const auto grasp = client_->send(client_->request(h, msg::GRASP, 30));
  ASSERT_TRUE(client_->wait_status(h, [](const auto& s) { return s.grip() == msg::GRIP_MOVING; }));
  const auto stop = client_->call(h, msg::STOP);
  ASSERT_TRUE(stop);
  EXPECT_EQ(stop->code(), msg::OK) << stop->message();
  const auto cancelled = client_->wait_reply(grasp);
  ASSERT_TRUE(cancelled);
  EXPECT_EQ(cancelled->code(), msg::CANCELLED);
  EXPECT_THAT(cancelled->message(), HasSubstr("cancelled"));
}

TEST_F(ServiceErrorsTest, NewerMotionSupersedesARunningGrasp) {
  const auto h = hand("slow", 1);
  ASSERT_EQ(client_->call(h, msg::INITIALIZE)->code(), msg::OK);
  const auto grasp = client_->send(client_->request(h, msg::GRASP, 30));
  ASSERT_TRUE(client_->wait_status(h, [](const auto& s) { return s.grip() == msg::GRIP_MOVING; }));
  EXPECT_EQ(client_->call(h, msg::MOVE, 100)->code(), msg::OK);
  const auto superseded = client_->wait_reply(grasp);
  ASSERT_TRUE(superseded);
  EXPECT_EQ(superseded->code(), msg::CANCELLED) << superseded->message();
}

TEST(ServiceBusDown, CommandsToAnUnreachableBoxReportBusDown) {
  // A port nobody listens on: bind, read it back, close.
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t length = sizeof address;
  ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
  ASSERT_EQ(::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length), 0);
  ::close(fd);
  const std::string spec = "tcp:127.0.0.1:" + std::to_string(ntohs(address.sin_port));
  TempFile config("buses:\n  - name: box\n    spec: " + spec + "\n    hands: [{id: 1}]\n");
  ServiceProcess service({"--config", config.path()});
  auto client = connected_client(service.name());
  ASSERT_TRUE(client);

  const auto info = client->wait_info(service.name(), [](const auto&) { return true; });
  ASSERT_TRUE(info);
  EXPECT_FALSE(info->buses()[0].link_up());
  const auto reply =
      client->call(DdsTestClient::hand(service.name(), "box", 1), msg::READ_REGISTER, 0, 0x0602);
  ASSERT_TRUE(reply);
  EXPECT_EQ(reply->code(), msg::BUS_DOWN) << reply->message();
  EXPECT_THAT(reply->message(), HasSubstr("box"));
}

TEST(ServiceAdmin, AllowedAdministrativeCommandsReachTheHand) {
  TempFile config(R"(
allow_admin: true
buses:
  - {name: bus0, spec: sim, sim: {reply_delay_ms: 1}, hands: [{id: 1}]}
)");
  ServiceProcess service({"--config", config.path()});
  auto client = connected_client(service.name());
  ASSERT_TRUE(client);
  const auto h = DdsTestClient::hand(service.name(), "bus0", 1);
  EXPECT_TRUE(client->wait_info(service.name(), [](const auto& i) { return i.admin_allowed(); }));
  const auto id = client->call(h, msg::SET_CAN_ID, 7);
  ASSERT_TRUE(id);
  EXPECT_EQ(id->code(), msg::OK) << id->message();
  const auto baud = client->call(h, msg::SET_BAUD_RATE, 2);
  ASSERT_TRUE(baud);
  EXPECT_EQ(baud->code(), msg::OK) << baud->message();
  // Both are stored, to take effect after a reboot: the hand still answers on 1.
  EXPECT_EQ(client->call(h, msg::READ_REGISTER, 0, 0x1201)->value(), 7);
  EXPECT_EQ(client->call(h, msg::READ_REGISTER, 0, 0x1401)->value(), 2);
}

}  // namespace
}  // namespace dh3::test
