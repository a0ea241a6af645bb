// The transfer-box server behind dh3-sim, in-process on a real loopback socket:
// opening, serving frames, the control channel, stopping.

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <string>
#include <thread>

#include "dh3/sim_server/transfer_box_server.hpp"
#include "support/raw_tcp_client.hpp"
#include "unit/sim/server_test_support.hpp"

namespace dh3::sim {
namespace {

using namespace std::chrono_literals;
using dh3::test::RawTcpClient;
using test::Pipe;
using test::read_line;
using test::write_text;
constexpr auto hand = test::fast_hand;

constexpr auto kDeadline = 10s;

/// A server running on its own thread until destroyed.
class Running : public test::ServerThread<TransferBoxServer> {
 public:
  explicit Running(TransferBoxServerOptions options, const Clock& clock = SystemClock::instance())
      : ServerThread(open_or_null(std::move(options), clock)) {}

 private:
  static std::unique_ptr<TransferBoxServer> open_or_null(TransferBoxServerOptions options,
                                                         const Clock& clock) {
    auto opened = TransferBoxServer::open(std::move(options), clock);
    EXPECT_TRUE(opened.ok());
    return opened ? std::move(opened.value()) : nullptr;
  }
};

TEST(TransferBoxServer, ListensOnAFreePortAndAnswersFrames) {
  TransferBoxServerOptions options;
  options.hands = {hand(1), hand(2)};
  Running running(options);
  ASSERT_NE(running.server().port(), 0);
  EXPECT_EQ(running.server().address(), "127.0.0.1:" + std::to_string(running.server().port()));

  RawTcpClient box(running.server().port());
  ASSERT_TRUE(box.connected());
  box.send_hex("FF FE FD FC 02 05 02 01 00 1E 00 00 00 FB");
  EXPECT_EQ(box.read_hex(14, kDeadline), "FF FE FD FC 02 05 02 01 00 1E 00 00 00 FB");
  box.send_hex(
      "FF FE FD FC 01 08 01 01 00 00 00 00 00 FB FF FE FD FC 01 08 02 01 00 00 00 00 00 FB");
  EXPECT_EQ(box.read_hex(14, kDeadline), "FF FE FD FC 01 08 01 01 00 A5 00 00 00 FB");
  EXPECT_EQ(box.read_hex(14, kDeadline), "FF FE FD FC 01 08 02 01 00 00 00 00 00 FB");
  EXPECT_EQ(box.read_hex(14, kDeadline), "FF FE FD FC 01 08 02 00 00 00 00 00 00 FB");
}

TEST(TransferBoxServer, AClientLeavingMidFrameDoesNotDisturbOthers) {
  TransferBoxServerOptions options;
  options.hands = {hand(1)};
  Running running(options);
  {
    RawTcpClient leaving(running.server().port());
    leaving.send_hex("FF FE FD FC 01 13");
  }
  RawTcpClient box(running.server().port());
  box.send_hex("FF FE FD FC 01 13 01 00 00 00 00 00 00 FB");
  EXPECT_EQ(box.read_hex(14, kDeadline), "FF FE FD FC 01 13 01 00 00 00 02 01 04 FB");
}

/// Two requests to hand 1 with a 10-minute minimum interval, read an hour apart
/// by the fake clock but sent within one round trip of the test; returns the
/// interval violations the server counted.
std::uint64_t violations_of_two_reads_an_hour_apart(bool kernel_timestamps) {
  FakeClock clock;
  TransferBoxServerOptions options;
  options.hands = {hand(1)};
  options.min_interval = 10min;
  options.kernel_timestamps = kernel_timestamps;
  Running running(options, clock);
  EXPECT_TRUE(running.started());
  if (!running.started()) return 0;
  RawTcpClient box(running.server().port());
  const std::string version = "FF FE FD FC 01 13 01 00 00 00 02 01 04 FB";
  box.send_hex("FF FE FD FC 01 13 01 00 00 00 00 00 00 FB");
  EXPECT_EQ(box.read_hex(14, kDeadline), version);
  clock.advance(1h);
  box.send_hex("FF FE FD FC 01 13 01 00 00 00 00 00 00 FB");
  EXPECT_EQ(box.read_hex(14, kDeadline), version);
  running.stop();
  return running.server().interval_violations();
}

TEST(TransferBoxServer, TimesTheIntervalCheckByTheKernelsReceiveStamp) {
  // The loop's wake-up is no part of the service's spacing: what counts is
  // when the frames reached the socket, a round trip apart here.
  EXPECT_EQ(violations_of_two_reads_an_hour_apart(true), 1u);
}

TEST(TransferBoxServer, TimesTheIntervalCheckByTheReadTimeWithoutKernelStamps) {
  EXPECT_EQ(violations_of_two_reads_an_hour_apart(false), 0u) << "an hour apart by the clock";
}

TEST(TransferBoxServer, RefusesAnAddressThatIsNotIpv4) {
  TransferBoxServerOptions options;
  options.host = "hand.example";
  auto opened = TransferBoxServer::open(options, SystemClock::instance());
  ASSERT_FALSE(opened.ok());
  EXPECT_EQ(opened.error(), ServerError::bad_address);
}

TEST(TransferBoxServer, TheControlChannelAnswersEachLineAndQuitEndsTheRun) {
  Pipe control_in;
  Pipe control_out;
  TransferBoxServerOptions options;
  options.hands = {hand(1), hand(4)};
  options.control_in = control_in.read_end();
  options.control_out = control_out.write_end();
  Running running(options);

  write_text(control_in.write_end(), "hands\n  object 4 30 \n\nobject 4 x\r\n");
  EXPECT_EQ(read_line(control_out.read_end()), "ok hands 1 4");
  EXPECT_EQ(read_line(control_out.read_end()), "ok object 4 30");
  EXPECT_EQ(read_line(control_out.read_end()), "error position must be 0-100 or none");
  write_text(control_in.write_end(), "quit\n");
  EXPECT_EQ(read_line(control_out.read_end()), "ok quit");
  running.join();  // returns without request_stop()
}

TEST(TransferBoxServer, ServesOnWhenTheControlChannelCloses) {
  Pipe control_in;
  TransferBoxServerOptions options;
  options.hands = {hand(1)};
  options.control_in = control_in.read_end();
  Running running(options);
  control_in.close_write();
  RawTcpClient box(running.server().port());
  box.send_hex("FF FE FD FC 01 13 01 00 00 00 00 00 00 FB");
  EXPECT_EQ(box.read_hex(14, kDeadline), "FF FE FD FC 01 13 01 00 00 00 02 01 04 FB");
}

TEST(TransferBoxServer, ExecuteChangesTheHands) {
  TransferBoxServerOptions options;
  options.hands = {hand(1)};
  auto opened = TransferBoxServer::open(options, SystemClock::instance());
  ASSERT_TRUE(opened.ok());
  TransferBoxServer& server = *opened.value();
  EXPECT_EQ(server.execute("mute 1"), "ok mute 1");
  EXPECT_NE(server.execute("state 1").find("muted=1"), std::string::npos);
  EXPECT_EQ(server.execute("unmute 1"), "ok unmute 1");
  EXPECT_EQ(server.execute("delay 1 -3"), "error delay takes milliseconds >= 0");
  EXPECT_EQ(server.execute("corrupt 1"), "error corrupt takes ID and a value");
  EXPECT_EQ(server.execute("drop 0"), "error '0' is no hand ID (1-255)");
  EXPECT_EQ(server.execute("reboot 1"), "ok reboot 1 (now ID 1)");
  EXPECT_EQ(server.execute("kick"), "ok kick 0");
}

}  // namespace
}  // namespace dh3::sim
