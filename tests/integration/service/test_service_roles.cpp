// Least privilege under DDS Security: dh3-service, with allow_admin on and
// the test PKI (deploy/security/make-test-pki.sh), takes an administrative
// command (SET_CAN_ID, SET_BAUD_RATE) only from the admin request topic,
// which only an admin identity's permissions let a participant publish. An
// operator's administrative command is DENIED and puts nothing on the bus,
// whether it comes through the client library or straight on the command
// request topic; the admin's runs. The service sits behind a recording proxy
// of the transfer box, so what reached the bus is seen byte for byte.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <filesystem>

#include "dh3/client.hpp"
#include "service_fixture.hpp"
#include "support/test_pki.hpp"

namespace dh3::test {
namespace {

namespace fs = std::filesystem;
using ::testing::Contains;
using ::testing::HasSubstr;
using ::testing::IsEmpty;

constexpr std::chrono::seconds kDeadline{20};

class AdminRoleTest : public ::testing::Test {
 protected:
  // One PKI for the suite, granting this test's domain: making keys is slow.
  static void SetUpTestSuite() {
    pki_ = make_test_pki(std::string(DH3_SOURCE_DIR) + "/deploy/security/make-test-pki.sh",
                         test_domain(), "roles", {"--force"});
    made_ = !pki_.empty();
  }
  static void TearDownTestSuite() { remove_test_pki(pki_); }

  void SetUp() override {
    ASSERT_TRUE(made_) << "make-test-pki.sh failed into " << pki_;
    ASSERT_NE(sim_.port(), 0);
    ASSERT_NE(proxy_.port(), 0);
    ASSERT_TRUE(service_.started());
  }

  /// A raw participant of the contract with the test PKI's `identity`, once
  /// the service answers it.
  std::unique_ptr<DdsTestClient> raw_client(const std::string& identity) {
    auto client = std::make_unique<DdsTestClient>(test_domain(), "dh3-test " + identity,
                                                  DdsTestClient::Replies::all,
                                                  DdsTestClient::Credentials{pki_, identity});
    if (!client->ok() || !client->wait_for_service(service_.name(), kDeadline)) return nullptr;
    return client;
  }

  ClientOptions library_options(const std::string& identity) const {
    ClientOptions options;
    options.domain = test_domain();
    options.default_timeout = kDeadline;
    options.participant_name = "dh3-test " + identity;
    options.security_dir = pki_;
    options.security_identity = identity;
    return options;
  }

  /// The frames the service wrote to the box since `from` bytes.
  std::vector<std::string> writes_since(std::size_t from) {
    const auto sent = proxy_.sent();
    const std::vector<std::uint8_t> later(sent.begin() + static_cast<std::ptrdiff_t>(from),
                                          sent.end());
    return written_frames(frames_as_hex(later));
  }

  static inline std::string pki_;
  static inline bool made_ = false;
  SimProcess sim_{{"--hands", "1", "--init-time-ms", "50"}};
  RecordingProxy proxy_{sim_.port()};
  TempFile config_{"allow_admin: true\ndds:\n  security:\n    dir: " + pki_ +
                   "\n    identity: service\nbuses:\n  - name: box\n    spec: " +
                   proxy_.bus_spec() + "\n    command_interval_ms: 2\n    hands: [{id: 1}]\n"};
  ServiceProcess service_{{"--config", config_.path()}};
  [[nodiscard]] std::string hand_name() const { return service_.name() + "/box/1"; }
  [[nodiscard]] msg::HandAddress hand() const {
    return DdsTestClient::hand(service_.name(), "box", 1);
  }
};

TEST_F(AdminRoleTest, AnOperatorsAdminCommandsAreDeniedAndReachNoBus) {
  auto op = raw_client("operator");
  ASSERT_TRUE(op) << "the operator found no service";
  // Its own access control refuses it the admin topic's writer.
  EXPECT_FALSE(op->has_admin_writer());
  const std::size_t before = proxy_.sent().size() / 14 * 14;

  // Straight on the command request topic, as a participant of any program may.
  for (const auto& [command, value] :
       {std::pair{msg::SET_CAN_ID, 2}, std::pair{msg::SET_BAUD_RATE, 0}}) {
    const auto reply = op->call(hand(), command, value);
    ASSERT_TRUE(reply) << "no reply";
    EXPECT_EQ(reply->code(), msg::DENIED) << reply->message();
    EXPECT_THAT(reply->message(), HasSubstr("only on dh3/admin_request"));
    EXPECT_THAT(reply->message(), HasSubstr("admin identity"));
  }

  // Through the client library: refused at once, nothing sent.
  Client library(library_options("operator"));
  ASSERT_TRUE(library.connected()) << library.error();
  auto hand = library.wait_for_hand(hand_name());
  ASSERT_TRUE(hand) << hand.message();
  const Reply refused = hand->set_can_id(2);
  EXPECT_EQ(refused.code, Code::denied);
  EXPECT_THAT(refused.message, HasSubstr("not permitted to publish administrative requests"));
  EXPECT_THAT(refused.message, HasSubstr("'operator' is no admin"));
  // The operator still drives: a command of its own role is served.
  EXPECT_EQ(hand->initialize().code, Code::ok);

  EXPECT_THAT(writes_since(before), ::testing::Not(Contains(HasSubstr("FF FE FD FC 01 12 01 01"))));
  EXPECT_THAT(writes_since(before), ::testing::Not(Contains(HasSubstr("FF FE FD FC 01 14 01 01"))));
}

TEST_F(AdminRoleTest, TheAdminsAdminCommandRunsOnTheBus) {
  Client admin(library_options("admin"));
  ASSERT_TRUE(admin.connected()) << admin.error();
  auto hand = admin.wait_for_hand(hand_name());
  ASSERT_TRUE(hand) << hand.message();
  const std::size_t before = proxy_.sent().size() / 14 * 14;
  const Reply reply = hand->set_baud_rate(0);
  EXPECT_EQ(reply.code, Code::ok) << reply.message;
  EXPECT_THAT(writes_since(before), Contains("FF FE FD FC 01 14 01 01 00 00 00 00 00 FB"));
}

TEST_F(AdminRoleTest, TheTopicDecidesNotTheIdentity) {
  auto admin = raw_client("admin");
  ASSERT_TRUE(admin) << "the admin found no service";
  ASSERT_TRUE(admin->has_admin_writer());
  ASSERT_TRUE(admin->wait_admin_reader());
  const std::size_t before = proxy_.sent().size() / 14 * 14;
  // An admin's administrative command on the command request topic is
  // refused like anyone's: what the permissions grant is the topic.
  const auto on_commands = admin->call(hand(), msg::SET_CAN_ID, 2);
  ASSERT_TRUE(on_commands);
  EXPECT_EQ(on_commands->code(), msg::DENIED) << on_commands->message();
  // The admin topic carries administrative commands only.
  const auto move = admin->wait_reply(admin->send_admin(admin->request(hand(), msg::MOVE, 30)));
  ASSERT_TRUE(move);
  EXPECT_EQ(move->code(), msg::INVALID_ARGUMENT) << move->message();
  EXPECT_THAT(move->message(), HasSubstr("takes only SET_CAN_ID and SET_BAUD_RATE"));
  EXPECT_THAT(writes_since(before), IsEmpty());

  const auto baud =
      admin->wait_reply(admin->send_admin(admin->request(hand(), msg::SET_BAUD_RATE, 0)));
  ASSERT_TRUE(baud);
  EXPECT_EQ(baud->code(), msg::OK) << baud->message();
  EXPECT_THAT(writes_since(before), Contains("FF FE FD FC 01 14 01 01 00 00 00 00 00 FB"));
}

}  // namespace
}  // namespace dh3::test
