// `dh3-sim --can` on a real vcan interface, driven through a raw CAN socket of
// the test's own: the hands' replies as another node on the bus sees them, the
// interval check with the kernel's receive timestamps, and the refusals. Needs
// a kernel with CAN and the right to create a vcan (tests/kernel/ runs these
// inside one); elsewhere every test skips with the reason.

#include <gtest/gtest.h>
#include <linux/can.h>
#include <net/if.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstring>
#include <optional>
#include <string>
#include <thread>

#include "dh3/bus/socketcan_bus.hpp"
#include "dh3/protocol/codec.hpp"
#include "support/process.hpp"
#include "support/raw_tcp_client.hpp"
#include "kernel/can_interfaces.hpp"

namespace {

using namespace std::chrono_literals;
using dh3::test::OwnVcan;
using dh3::test::Process;

constexpr auto kDeadline = 10s;
// The protocol document's interval, kept by this test's own frames.
constexpr auto kPacing = 25ms;

/// An unfiltered raw CAN socket bound to `interface`; -1 if it cannot be had.
int open_raw_socket(const std::string& interface) {
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) return -1;
  sockaddr_can address{};
  address.can_family = AF_CAN;
  address.can_ifindex = static_cast<int>(::if_nametoindex(interface.c_str()));
  if (::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

/// dh3-sim --can on a vcan of the test's own, and a raw socket on that vcan.
class Dh3SimCanKernel : public ::testing::Test {
 protected:
  void SetUp() override {
    if (const std::string problem = dh3::bus::kernel_can_support_problem(); !problem.empty()) {
      GTEST_SKIP() << problem;
    }
    vcan_ = std::make_unique<OwnVcan>("dh3simvcan");
    if (!vcan_->ready()) GTEST_SKIP() << vcan_->why();
    bus_ = open_raw_socket(vcan_->name());
    ASSERT_GE(bus_, 0) << "raw CAN socket on " << vcan_->name() << ": " << std::strerror(errno);
  }
  void TearDown() override {
    if (bus_ >= 0) ::close(bus_);
  }

  void start_sim(std::vector<std::string> args) {
    std::vector<std::string> all{"--can",   vcan_->name(), "--init-time-ms", "100",
                                 "--speed", "1000",        "--log-level",    "warn"};
    all.insert(all.end(), args.begin(), args.end());
    sim_ = std::make_unique<Process>(DH3_SIM_PATH, all);
    ASSERT_TRUE(sim_->started());
  }

  std::string control(const std::string& command) {
    sim_->write_line(command);
    return sim_->read_line(kDeadline).value_or("<no answer>");
  }

  void send(canid_t id, std::string_view payload_hex) {
    can_frame frame{};
    frame.can_id = id;
    const auto bytes = dh3::test::bytes_from_hex(payload_hex);
    frame.len = static_cast<std::uint8_t>(bytes.size());
    std::copy(bytes.begin(), bytes.end(), frame.data);
    ASSERT_EQ(::write(bus_, &frame, sizeof frame), static_cast<ssize_t>(sizeof frame));
  }

  /// The next frame on the bus as "ID: payload", or "<nothing>" within `timeout`.
  std::string next_frame(std::chrono::milliseconds timeout = kDeadline) {
    pollfd p{bus_, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(timeout.count())) <= 0) return "<nothing>";
    can_frame frame{};
    if (::read(bus_, &frame, sizeof frame) != static_cast<ssize_t>(sizeof frame)) return "<error>";
    return std::to_string(frame.can_id) + ": " +
           dh3::protocol::to_hex(std::span(frame.data, frame.len));
  }

  /// Sends after the pacing interval and returns the next frame on the bus.
  std::string exchange(canid_t id, std::string_view payload_hex) {
    std::this_thread::sleep_for(kPacing);  // command pacing, not a wait for an event
    send(id, payload_hex);
    return next_frame();
  }

  std::unique_ptr<OwnVcan> vcan_;
  int bus_ = -1;
  std::unique_ptr<Process> sim_;
};

TEST_F(Dh3SimCanKernel, OneHandInitializesAndMovesOnARealVcan) {
  start_sim({"--hands", "1,2", "--min-interval-ms", "20"});
  EXPECT_EQ(sim_->wait_for_line("serving ", kDeadline), "serving 2 hands on " + vcan_->name());

  EXPECT_EQ(exchange(1, "08 01 01 00 00 00 00 00"), "1: 08 01 01 00 A5 00 00 00");
  EXPECT_EQ(exchange(1, "08 02 01 00 00 00 00 00"), "1: 08 02 01 00 00 00 00 00");
  EXPECT_EQ(next_frame(), "1: 08 02 00 00 00 00 00 00") << "unsolicited: initialization finished";
  EXPECT_EQ(exchange(1, "08 02 00 00 00 00 00 00"), "1: 08 02 00 00 01 00 00 00");
  EXPECT_EQ(exchange(1, "06 02 01 00 3C 00 00 00"), "1: 06 02 01 00 3C 00 00 00");
  std::string status;
  const auto deadline = std::chrono::steady_clock::now() + kDeadline;
  while (status != "1: 0F 01 00 00 02 00 00 00" && std::chrono::steady_clock::now() < deadline) {
    status = exchange(1, "0F 01 00 00 00 00 00 00");
  }
  EXPECT_EQ(status, "1: 0F 01 00 00 02 00 00 00") << "arrived";
  EXPECT_EQ(exchange(1, "06 02 00 00 00 00 00 00"), "1: 06 02 00 00 3C 00 00 00");
  EXPECT_EQ(exchange(2, "13 01 00 00 00 00 00 00"), "2: 13 01 00 00 00 02 01 04");
  EXPECT_EQ(control("violations"), "ok 0") << "this test kept 25 ms between frames";

  // Foreign traffic on the bus gets no answer; the next frame is hand 2's.
  send(CAN_EFF_FLAG | 1, "13 01 00 00 00 00 00 00");
  send(0x123, "13 01 00 00 00 00 00 00");
  send(1, "13 01 00");
  EXPECT_EQ(exchange(2, "05 02 00 00 00 00 00 00"), "2: 05 02 00 00 32 00 00 00");

  EXPECT_EQ(control("quit"), "ok quit");
  EXPECT_EQ(sim_->read_line(kDeadline), "interval violations: 0");
  const auto exit_status = sim_->wait_exit(kDeadline);
  ASSERT_TRUE(exit_status.has_value());
  EXPECT_EQ(WEXITSTATUS(*exit_status), 0);
}

TEST_F(Dh3SimCanKernel, TheIntervalIsMeasuredWhenFramesReachTheSocketNotWhenTheSimReads) {
  start_sim({"--hands", "1", "--min-interval-ms", "20"});
  ASSERT_TRUE(sim_->wait_for_line("serving ", kDeadline));
  EXPECT_EQ(exchange(1, "13 01 00 00 00 00 00 00"), "1: 13 01 00 00 00 02 01 04");

  // dh3-sim stopped: both frames wait in its socket and are read together,
  // but they reached it 50 ms apart.
  ASSERT_TRUE(sim_->send_signal(SIGSTOP));
  std::this_thread::sleep_for(kPacing);
  send(1, "13 01 00 00 00 00 00 00");
  std::this_thread::sleep_for(50ms);  // the spacing under test
  send(1, "05 02 00 00 00 00 00 00");
  ASSERT_TRUE(sim_->send_signal(SIGCONT));
  EXPECT_EQ(next_frame(), "1: 13 01 00 00 00 02 01 04");
  EXPECT_EQ(next_frame(), "1: 05 02 00 00 32 00 00 00");
  EXPECT_EQ(control("violations"), "ok 0");

  // Back to back: one violation.
  std::this_thread::sleep_for(kPacing);
  send(1, "13 01 00 00 00 00 00 00");
  send(1, "05 02 00 00 00 00 00 00");
  EXPECT_EQ(next_frame(), "1: 13 01 00 00 00 02 01 04");
  EXPECT_EQ(next_frame(), "1: 05 02 00 00 32 00 00 00");
  EXPECT_EQ(control("violations"), "ok 1");

  ASSERT_TRUE(sim_->send_signal(SIGTERM));
  EXPECT_EQ(sim_->read_line(kDeadline), "interval violations: 1");
  const auto exit_status = sim_->wait_exit(kDeadline);
  ASSERT_TRUE(exit_status.has_value());
  EXPECT_EQ(WEXITSTATUS(*exit_status), 0);
}

TEST_F(Dh3SimCanKernel, TheHandsWaitOutTheInterfaceGoingDownAndUp) {
  start_sim({"--hands", "1"});
  ASSERT_TRUE(sim_->wait_for_line("serving ", kDeadline));
  EXPECT_EQ(exchange(1, "05 02 01 00 1E 00 00 00"), "1: 05 02 01 00 1E 00 00 00");
  ASSERT_TRUE(vcan_->set_up(false));
  ASSERT_TRUE(vcan_->set_up(true));
  // The test's own socket may report the down once (ENETDOWN); take it.
  can_frame ignored{};
  [[maybe_unused]] const ssize_t pending_error =
      ::recv(bus_, &ignored, sizeof ignored, MSG_DONTWAIT);
  EXPECT_EQ(exchange(1, "05 02 00 00 00 00 00 00"), "1: 05 02 00 00 1E 00 00 00");
  EXPECT_EQ(control("quit"), "ok quit");
}

TEST_F(Dh3SimCanKernel, TheHandsComeBackWhenTheInterfaceIsCreatedAgain) {
  start_sim({"--hands", "1"});
  ASSERT_TRUE(sim_->wait_for_line("serving ", kDeadline));
  EXPECT_EQ(exchange(1, "05 02 01 00 1E 00 00 00"), "1: 05 02 01 00 1E 00 00 00");
  ASSERT_TRUE(vcan_->recreate());
  // Deleting the interface unbound the test's socket too.
  ::close(bus_);
  bus_ = open_raw_socket(vcan_->name());
  ASSERT_GE(bus_, 0);
  // dh3-sim reopens the interface every 0.5 s; until then requests are lost.
  std::string reply;
  const auto deadline = std::chrono::steady_clock::now() + kDeadline;
  do {
    std::this_thread::sleep_for(kPacing);  // command pacing, not a wait for time
    send(1, "05 02 00 00 00 00 00 00");
    reply = next_frame(200ms);
  } while (reply == "<nothing>" && std::chrono::steady_clock::now() < deadline);
  EXPECT_EQ(reply, "1: 05 02 00 00 1E 00 00 00") << "the hand kept its force (30)";
  EXPECT_EQ(control("quit"), "ok quit");
}

TEST_F(Dh3SimCanKernel, RefusesAnInterfaceThatIsMissingDownOrNotCan) {
  for (const std::string& interface : {std::string("dh3nosuchcan0"), std::string("lo")}) {
    Process sim(DH3_SIM_PATH, {"--can", interface});
    const auto status = sim.wait_exit(kDeadline);
    ASSERT_TRUE(status.has_value()) << interface;
    EXPECT_EQ(WEXITSTATUS(*status), 1) << interface;
  }
  ASSERT_TRUE(vcan_->set_up(false));
  Process sim(DH3_SIM_PATH, {"--can", vcan_->name()});
  const auto status = sim.wait_exit(kDeadline);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(WEXITSTATUS(*status), 1) << "a vcan that is down";
}

}  // namespace
