// Processes that die: dh3-service killed (SIGKILL) and started again while its
// clients run on, and clients killed while their requests are pending.
// A SIGKILLed participant is noticed by Fast DDS only when its lease ends, so
// nothing here depends on that being quick: deadlines are generous.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <csignal>

#include "dh3/client.hpp"
#include "dh3/registers.hpp"
#include "reliability_fixture.hpp"

namespace dh3::test {
namespace {

using ::testing::AnyOf;
using ::testing::Eq;
using ::testing::StartsWith;

constexpr std::chrono::seconds kRestartDeadline{60};

std::string sim_bus_config() {
  return "buses:\n  - name: bus0\n    spec: sim\n    command_interval_ms: 2\n"
         "    poll_interval_idle_ms: 50\n"
         "    sim: {reply_delay_ms: 1, init_time_ms: 50, position_speed: 400}\n"
         "    hands: [{id: 1}, {id: 2}, {id: 3}]\n";
}

TEST(ServiceKilled, ClientsRunningThroughTheOutageRecoverWithoutRestarting) {
  TempFile config(sim_bus_config());
  const std::vector<std::string> args{"--config", config.path(), "--log-level", "warn"};
  auto service = std::make_unique<ServiceProcess>(args);
  ASSERT_TRUE(service->started());
  const std::string name = service->name();
  const auto address = [&](std::uint16_t id) { return DdsTestClient::hand(name, "bus0", id); };

  // Two raw DDS clients and one dh3::Client, all living through the outage.
  auto first = connected_client(name, "dh3-test-a");
  auto second = connected_client(name, "dh3-test-b");
  ASSERT_TRUE(first && second);
  ClientOptions options;
  options.domain = test_domain();
  options.default_timeout = std::chrono::seconds(20);
  Client library(options);
  ASSERT_TRUE(library.connected()) << library.error();
  ASSERT_TRUE(library.wait_for_service(name, std::chrono::seconds(20)));
  Hand library_hand = library.hand(HandAddress{name, "bus0", 3});
  ASSERT_TRUE(library_hand.read(reg::firmware_version));
  ASSERT_EQ(first->call(address(1), msg::INITIALIZE)->code(), msg::OK);

  service->process().send_signal(SIGKILL);
  ASSERT_TRUE(service->process().wait_exit(std::chrono::seconds(20)));
  service.reset();

  // During the outage: no reply for the raw clients, a clear error for the
  // library's calls once their deadline passes.
  std::vector<std::uint64_t> outage;
  for (std::uint16_t id = 1; id <= 3; ++id) {
    outage.push_back(first->send(first->request(address(id), msg::READ_REGISTER, 0, 0x0602)));
  }
  EXPECT_FALSE(first->wait_reply(outage.back(), std::chrono::seconds(3)));
  const Reply lost = library_hand.read(reg::position, std::chrono::seconds(3));
  EXPECT_FALSE(lost);
  EXPECT_THAT(lost.code, AnyOf(Eq(Code::no_reply), Eq(Code::service_lost), Eq(Code::no_service)))
      << to_string(lost.code) << ": " << lost.message;
  EXPECT_FALSE(lost.message.empty());

  // The same service comes back; every client works again as it is.
  ServiceProcess restarted(args, name);
  ASSERT_TRUE(restarted.started());
  ASSERT_TRUE(first->wait_for_service(name, kRestartDeadline));
  ASSERT_TRUE(second->wait_for_service(name, kRestartDeadline));
  std::vector<std::uint64_t> first_seqs;
  std::vector<std::uint64_t> second_seqs;
  for (int round = 0; round < 5; ++round) {
    for (std::uint16_t id = 1; id <= 3; ++id) {
      first_seqs.push_back(first->send(first->request(address(id), msg::READ_REGISTER, 0, 0x1301)));
      second_seqs.push_back(
          second->send(second->request(address(id), msg::READ_REGISTER, 0, 0x0502)));
    }
  }
  for (const auto& reply : expect_one_reply_each(*first, first_seqs)) {
    EXPECT_EQ(reply.code(), msg::OK) << reply.message();
    EXPECT_EQ(reply.value(), 0x04010200);
  }
  for (const auto& reply : expect_one_reply_each(*second, second_seqs)) {
    EXPECT_EQ(reply.code(), msg::OK) << reply.message();
  }
  const Reply again = library_hand.read(reg::firmware_version, kRestartDeadline);
  EXPECT_TRUE(again) << to_string(again.code) << ": " << again.message;
  EXPECT_EQ(again.value, 0x04010200);
  // The restarted service knows nothing of the old one's state.
  const auto move = first->call(address(1), msg::MOVE, 50);
  ASSERT_TRUE(move);
  EXPECT_EQ(move->code(), msg::NOT_INITIALIZED) << move->message();
  EXPECT_EQ(first->call(address(1), msg::INITIALIZE)->code(), msg::OK);
  EXPECT_EQ(first->call(address(1), msg::MOVE, 50)->code(), msg::OK);
  // A request of the outage is answered at most once, if at all.
  for (const auto seq : outage) EXPECT_LE(first->reply_count(seq), 1U) << "request " << seq;
}

// A service that cannot run (stopped, here by SIGSTOP; a wedged process
// alike) stops asserting that it lives: the caller's request, never answered,
// ends SERVICE_LOST well before the call's own deadline, saying that the
// command may or may not have reached the hand (the frozen service still holds
// it). Continued, the same service serves again.
TEST(ServiceStopped, ARequestItNeverAnsweredIsReportedLostAndItServesAgainWhenContinued) {
  TempFile config(sim_bus_config());
  ServiceProcess service({"--config", config.path(), "--log-level", "warn"});
  ASSERT_TRUE(service.started());
  ClientOptions options;
  options.domain = test_domain();
  Client library(options);
  ASSERT_TRUE(library.connected()) << library.error();
  ASSERT_TRUE(library.wait_for_service(service.name(), std::chrono::seconds(20)));
  Hand hand = library.hand(HandAddress{service.name(), "bus0", 1});
  ASSERT_TRUE(hand.read(reg::firmware_version, std::chrono::seconds(20)));

  service.process().send_signal(SIGSTOP);
  // The deadline is the participant lease's: only the owner liveliness ends it sooner.
  const Reply unread = hand.read(reg::position, std::chrono::seconds(15));
  service.process().send_signal(SIGCONT);
  EXPECT_EQ(unread.code, Code::service_lost) << unread.message;
  EXPECT_THAT(unread.message, ::testing::HasSubstr("killed, frozen or cut off"));
  EXPECT_THAT(unread.message, ::testing::HasSubstr("may or may not have reached the hand"));
  // Running again, it answers as before, and its hands are online again.
  EXPECT_TRUE(hand.read(reg::firmware_version, std::chrono::seconds(20)));
  EXPECT_TRUE(
      hand.wait_until([](const HandStatus& s) { return s.online; }, std::chrono::seconds(20)));
}

/// dh3ctl processes are the clients that die: each asks hand 1-3 for its
/// firmware version; the hands answer late, so the requests are pending at the
/// service when the clients are killed.
class ClientKilled : public BoxTest {};

TEST_F(ClientKilled, TheServiceAndItsOtherClientsCarryOn) {
  BoxOptions options;
  options.reply_timeout_ms = 5000;
  ASSERT_NO_FATAL_FAILURE(start(options));
  for (std::uint16_t id = 1; id <= 3; ++id) {
    ASSERT_THAT(sim_->control("delay " + std::to_string(id) + " 2500"), StartsWith("ok"));
  }
  // Hand N's firmware version read: "FF FE FD FC 0N 13 01 00 ...".
  const auto version_reads = [&](std::uint16_t id) {
    const std::string prefix = "FF FE FD FC 0" + std::to_string(id) + " 13 01 00";
    std::size_t n = 0;
    for (const auto& frame : frames_as_hex(proxy_->sent())) n += frame.starts_with(prefix);
    return n;
  };
  std::vector<std::size_t> before;
  for (std::uint16_t id = 1; id <= 3; ++id) before.push_back(version_reads(id));
  std::vector<std::unique_ptr<Process>> doomed;
  for (std::uint16_t id = 1; id <= 3; ++id) {
    doomed.push_back(std::make_unique<Process>(
        DH3CTL_PATH,
        std::vector<std::string>{"--domain", std::to_string(test_domain()), "--timeout", "30",
                                 "version", service_->name() + "/box/" + std::to_string(id)},
        Process::Stdin::dev_null));
    ASSERT_TRUE(doomed.back()->started());
  }
  const auto all_sent = [&] {
    for (std::uint16_t id = 1; id <= 3; ++id) {
      if (version_reads(id) <= before[id - 1]) return false;
    }
    return true;
  };
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (!all_sent() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));  // polling, not a wait for time
  }
  ASSERT_TRUE(all_sent()) << "the dh3ctl requests never reached the hands";
  // A client that stays: its requests are queued behind the doomed ones.
  std::vector<std::uint64_t> survivor;
  for (std::uint16_t id = 1; id <= 3; ++id) {
    survivor.push_back(client_->send(client_->request(hand(id), msg::READ_REGISTER, 0, 0x0602)));
  }
  for (auto& process : doomed) {
    process->send_signal(SIGKILL);
    const auto status = process->wait_exit(std::chrono::seconds(10));
    ASSERT_TRUE(status);
    EXPECT_TRUE(WIFSIGNALED(*status)) << "dh3ctl ended before it was killed";
  }
  // The dead clients' replies go nowhere; the survivor's come as usual.
  for (const auto& reply : expect_one_reply_each(*client_, survivor)) {
    EXPECT_EQ(reply.code(), msg::OK) << reply.message();
  }
  for (std::uint16_t id = 1; id <= 3; ++id) {
    ASSERT_THAT(sim_->control("delay " + std::to_string(id) + " 0"), StartsWith("ok"));
  }
  EXPECT_TRUE(service_alive());
  for (const msg::CommandType command : {msg::INITIALIZE, msg::MOVE}) {
    std::vector<std::uint64_t> seqs;
    for (std::uint16_t id = 1; id <= 3; ++id) {
      seqs.push_back(client_->send(client_->request(hand(id), command, 20 * id)));
    }
    for (const auto& reply : expect_one_reply_each(*client_, seqs)) {
      EXPECT_EQ(reply.code(), msg::OK) << reply.message();
    }
  }
  EXPECT_TRUE(client_->wait_status(hand(3), [](const auto& s) { return s.position() == 60; }));
  EXPECT_TRUE(service_alive());
}

}  // namespace
}  // namespace dh3::test
