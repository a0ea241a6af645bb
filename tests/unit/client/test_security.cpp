// libdh3client with DDS Security (ClientOptions::security_dir) against a fake
// service with the "service" credentials of deploy/security/make-test-pki.sh:
// the operator drives hands, the monitor (permitted to read statuses and
// events only) connects read-only and its commands end at once with DENIED,
// a client without credentials sees nothing, and bad credentials are an
// error() rather than an exception or a silently insecure client.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <future>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "dh3/client.hpp"
#include "fake_service.hpp"
#include "support/process.hpp"
#include "support/test_pki.hpp"
#include "support/test_domain.hpp"

namespace dh3 {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

constexpr std::chrono::seconds kDeadline{20};

using test::test_domain;
std::string service_name() {
  return "sec" + std::to_string(::getpid());
}

class ClientSecurity : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = test::make_test_pki(DH3_MAKE_TEST_PKI, test_domain(), "client");
    made_ = !dir_.empty();
  }
  static void TearDownTestSuite() { test::remove_test_pki(dir_); }
  void SetUp() override { ASSERT_TRUE(made_) << "make-test-pki.sh failed into " << dir_; }

  static ClientOptions options(const std::string& identity) {
    ClientOptions o;
    o.domain = test_domain();
    o.default_timeout = kDeadline;
    o.participant_name = "dh3-client " + identity;
    if (!identity.empty()) {
      o.security_dir = dir_;
      o.security_identity = identity;
    }
    return o;
  }

  static inline std::string dir_;
  static inline bool made_ = false;
};

TEST_F(ClientSecurity, TheOperatorDrivesAHand) {
  test::FakeService fake(test_domain(), service_name(), {1, 2}, dir_);
  ASSERT_TRUE(fake.ok());
  Client client(options("operator"));
  ASSERT_TRUE(client.connected()) << client.error();
  EXPECT_FALSE(client.read_only());
  const auto service = client.wait_for_service(service_name());
  ASSERT_TRUE(service) << service.message();
  ASSERT_EQ(service->buses.size(), 1U);  // it may read ServiceInfo
  auto hand = client.wait_for_hand(service_name() + "/bus0/1");
  ASSERT_TRUE(hand) << hand.message();
  const Reply reply = hand->move_to(30);
  EXPECT_EQ(reply.code, Code::ok) << reply.message;
  const auto requests = fake.wait_requests(1, kDeadline);
  ASSERT_EQ(requests.size(), 1U);
  EXPECT_EQ(requests.front().value(), 30);
}

TEST_F(ClientSecurity, TheMonitorWatchesButItsCommandsAreDeniedAtOnce) {
  test::FakeService fake(test_domain(), service_name(), {1, 2}, dir_);
  ASSERT_TRUE(fake.ok());
  Client monitor(options("monitor"));
  ASSERT_TRUE(monitor.connected()) << monitor.error();
  EXPECT_TRUE(monitor.read_only());

  auto hand = monitor.wait_for_hand(service_name() + "/hand1");
  ASSERT_TRUE(hand) << hand.message();
  const auto service = monitor.wait_for_service(service_name());
  ASSERT_TRUE(service) << service.message();
  EXPECT_TRUE(service->ready);

  std::mutex mutex;
  std::condition_variable cv;
  std::vector<HandEvent> events;
  auto subscription = hand->subscribe([&](const HandEvent& e) {
    std::lock_guard lock(mutex);
    events.push_back(e);
    cv.notify_all();
  });
  fake.publish_event(1, msg::EVENT_ARRIVED);
  {
    std::unique_lock lock(mutex);
    ASSERT_TRUE(cv.wait_for(lock, kDeadline, [&] { return !events.empty(); }));
    EXPECT_EQ(events.front().kind, EventKind::arrived);
  }

  auto pending = hand->move_to_async(80);
  ASSERT_EQ(pending.wait_for(std::chrono::seconds(0)), std::future_status::ready);
  const Reply reply = pending.get();
  EXPECT_EQ(reply.code, Code::denied);
  EXPECT_THAT(reply.message, HasSubstr("not permitted to publish command requests"));
  EXPECT_THAT(reply.message, HasSubstr("monitor"));

  // The operator's request is the only one the service ever gets.
  Client op(options("operator"));
  ASSERT_TRUE(op.connected()) << op.error();
  EXPECT_EQ(op.hand(hand->address()).move_to(40).code, Code::ok);
  const auto requests = fake.wait_requests(1, kDeadline);
  ASSERT_EQ(requests.size(), 1U);
  EXPECT_EQ(requests.front().client_id(), op.client_id());
}

TEST_F(ClientSecurity, AClientWithoutCredentialsSeesNothing) {
  test::FakeService fake(test_domain(), service_name(), {1, 2}, dir_);
  ASSERT_TRUE(fake.ok());
  // A secured client that does see the service bounds the wait below.
  Client op(options("operator"));
  ASSERT_TRUE(op.connected()) << op.error();
  ASSERT_TRUE(op.wait_for_hand(service_name() + "/bus0/1"));

  Client outsider(options(""));
  ASSERT_TRUE(outsider.connected()) << outsider.error();
  const auto found = outsider.wait_for_service(service_name(), std::chrono::seconds(3));
  EXPECT_FALSE(found);
  EXPECT_EQ(found.code(), Code::no_service);
  EXPECT_TRUE(outsider.hands().empty());
}

TEST_F(ClientSecurity, MissingCredentialsAreAnErrorNotAnException) {
  Client nobody(options("nobody"));
  EXPECT_FALSE(nobody.connected());
  EXPECT_THAT(nobody.error(), HasSubstr("nobody"));
  EXPECT_THAT(nobody.error(), HasSubstr("cert.pem"));
  EXPECT_EQ(nobody.hand({service_name(), "bus0", 1}).move_to(10).code, Code::not_connected);

  auto missing_dir = options("operator");
  missing_dir.security_dir = dir_ + "/nowhere";
  Client lost(missing_dir);
  EXPECT_FALSE(lost.connected());
  EXPECT_THAT(lost.error(), HasSubstr("DDS Security"));
}

TEST_F(ClientSecurity, CredentialsThatDoNotBelongTogetherAreRefused) {
  // The monitor's certificate with the operator's key, made by copying.
  const fs::path mixed = fs::path(dir_) / "mixed";
  fs::create_directories(mixed);
  fs::copy_file(fs::path(dir_) / "monitor" / "cert.pem", mixed / "cert.pem",
                fs::copy_options::overwrite_existing);
  fs::copy_file(fs::path(dir_) / "operator" / "key.pem", mixed / "key.pem",
                fs::copy_options::overwrite_existing);
  fs::copy_file(fs::path(dir_) / "monitor" / "permissions.p7s", mixed / "permissions.p7s",
                fs::copy_options::overwrite_existing);
  Client client(options("mixed"));
  EXPECT_FALSE(client.connected());
  EXPECT_THAT(client.error(), HasSubstr("did not accept the credentials of identity 'mixed'"));
}

struct CtlRun {
  int code = -1;
  std::string out;
  std::string err;
};

CtlRun dh3ctl(std::vector<std::string> args) {
  args.insert(args.begin(), "dh3ctl");
  std::vector<const char*> argv;
  for (const auto& arg : args) argv.push_back(arg.c_str());
  std::ostringstream out;
  std::ostringstream err;
  std::atomic<bool> interrupted{false};
  CtlRun result;
  result.code = ctl::run(static_cast<int>(argv.size()), argv.data(), out, err, interrupted);
  result.out = out.str();
  result.err = err.str();
  return result;
}

TEST_F(ClientSecurity, Dh3ctlAsMonitorShowsStatusAndRefusesCommands) {
  test::FakeService fake(test_domain(), service_name(), {1, 2}, dir_);
  ASSERT_TRUE(fake.ok());
  const std::string hand = service_name() + "/bus0/1";
  const std::vector<std::string> monitor = {
      "--domain", std::to_string(test_domain()), "--timeout", "20", "--security-dir",
      dir_,       "--security-identity",         "monitor"};
  auto with = [&](std::vector<std::string> tail) {
    auto args = monitor;
    args.insert(args.end(), tail.begin(), tail.end());
    return args;
  };
  const CtlRun status = dh3ctl(with({"--json", "status", hand}));
  EXPECT_EQ(status.code, ctl::kExitOk) << status.err;
  EXPECT_THAT(status.out, HasSubstr("\"position\":100"));
  const CtlRun list = dh3ctl(with({"list"}));
  EXPECT_EQ(list.code, ctl::kExitOk) << list.err;
  EXPECT_THAT(list.out, HasSubstr(service_name()));

  const CtlRun move = dh3ctl(with({"move", hand, "80"}));
  EXPECT_EQ(move.code, ctl::kExitFailed);
  EXPECT_THAT(move.err, HasSubstr("DENIED: not permitted to publish command requests"));
  const CtlRun scan = dh3ctl(with({"scan", service_name()}));
  EXPECT_EQ(scan.code, ctl::kExitFailed);
  EXPECT_THAT(scan.err, HasSubstr("DENIED"));
}

}  // namespace
}  // namespace dh3
