// SocketCanBus on the fd path it shares with real CAN sockets: the tests hand
// it one end of an AF_UNIX SOCK_SEQPACKET socketpair carrying struct can_frame
// and play the CAN interface on the other end. What the kernel's CAN_RAW_FILTER
// does cannot be seen through a socketpair; the user-space checks that repeat
// it can. The real kernel path is tested in tests/kernel/, inside a kernel
// with CAN.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <net/if.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <future>
#include <optional>
#include <string>
#include <thread>

#include "dh3/bus/socketcan_bus.hpp"
#include "dh3/protocol/codec.hpp"
#include "support/bus_wait.hpp"

namespace dh3::bus {
namespace {

using namespace std::chrono_literals;
using ::testing::HasSubstr;

can_frame make_can_frame(std::uint32_t can_id, std::vector<std::uint8_t> data) {
  can_frame frame{};
  frame.can_id = can_id;
  frame.len = static_cast<std::uint8_t>(data.size());
  std::copy_n(data.begin(), std::min<std::size_t>(data.size(), sizeof frame.data), frame.data);
  return frame;
}

/// Waits up to 10 s for one datagram on `fd`; nullopt if none came.
std::optional<std::vector<std::uint8_t>> read_datagram(int fd, int timeout_ms = 10000) {
  pollfd p{fd, POLLIN, 0};
  if (::poll(&p, 1, timeout_ms) <= 0) return std::nullopt;
  std::vector<std::uint8_t> bytes(128);
  const ssize_t n = ::recv(fd, bytes.data(), bytes.size(), MSG_DONTWAIT);
  if (n < 0) return std::nullopt;
  bytes.resize(static_cast<std::size_t>(n));
  return bytes;
}

void write_datagram(int fd, const void* data, std::size_t size) {
  ASSERT_EQ(::send(fd, data, size, MSG_NOSIGNAL), static_cast<ssize_t>(size));
}

void write_frame(int fd, const can_frame& frame) {
  write_datagram(fd, &frame, sizeof frame);
}

class SocketCanBusTest : public ::testing::Test {
 protected:
  /// A bus whose opener creates a fresh socketpair each time (or refuses while
  /// refuse_opens_ is set) and keeps the other end in peer_.
  std::unique_ptr<SocketCanBus> make_bus(const Clock& clock, SocketCanOptions options = {}) {
    CanSocketOpener opener = [this]() -> Result<UniqueFd, std::string> {
      ++opens_;
      if (refuse_opens_) return dh3::fail(std::string("interface is down (test)"));
      int fds[2];
      if (::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_NONBLOCK | SOCK_CLOEXEC, 0, fds) != 0) {
        return dh3::fail("socketpair: " + errno_text(errno));
      }
      peer_.reset(fds[1]);
      return UniqueFd(fds[0]);
    };
    return std::make_unique<SocketCanBus>("socketcan:test0", std::move(opener), clock, options);
  }

  UniqueFd peer_;
  int opens_ = 0;
  bool refuse_opens_ = false;
  FakeClock fake_clock_;
};

TEST_F(SocketCanBusTest, SendWritesOneStructCanFrame) {
  auto bus = make_bus(SystemClock::instance());
  ASSERT_EQ(bus->link_state(), LinkState::up);
  const auto message = protocol::make_write(1, protocol::reg::kPosition, 60);
  ASSERT_TRUE(bus->send(test::to_can_frame(message)).ok());

  const auto datagram = read_datagram(peer_.get());
  ASSERT_TRUE(datagram.has_value());
  ASSERT_EQ(datagram->size(), sizeof(can_frame));
  can_frame seen{};
  std::memcpy(&seen, datagram->data(), sizeof seen);
  EXPECT_EQ(seen.can_id, 1u);  // standard frame, no flags
  EXPECT_EQ(seen.len, 8);
  // spec "Position": 06 02 01 00 3C 00 00 00
  const std::vector<std::uint8_t> payload(seen.data, seen.data + 8);
  EXPECT_EQ(payload, (std::vector<std::uint8_t>{0x06, 0x02, 0x01, 0x00, 0x3C, 0x00, 0x00, 0x00}));
  EXPECT_EQ(bus->counters().frames_sent, 1u);
}

TEST_F(SocketCanBusTest, SendAcceptsEveryStandardIdAndRejectsInvalidFrames) {
  auto bus = make_bus(SystemClock::instance());
  CanFrame frame;
  frame.id = 0x7FF;
  EXPECT_TRUE(bus->send(frame).ok());
  frame.id = 0x800;
  EXPECT_EQ(bus->send(frame).error(), BusError::frame_invalid);
  frame.id = 1;
  frame.length = 9;
  EXPECT_EQ(bus->send(frame).error(), BusError::frame_invalid);
  frame.length = 2;  // short frames are legal CAN
  frame.data = {0xAA, 0xBB};
  EXPECT_TRUE(bus->send(frame).ok());

  auto first = read_datagram(peer_.get());
  ASSERT_TRUE(first.has_value());
  can_frame seen{};
  std::memcpy(&seen, first->data(), sizeof seen);
  EXPECT_EQ(seen.can_id, 0x7FFu);
  auto second = read_datagram(peer_.get());
  ASSERT_TRUE(second.has_value());
  std::memcpy(&seen, second->data(), sizeof seen);
  EXPECT_EQ(seen.can_id, 1u);
  EXPECT_EQ(seen.len, 2);
  EXPECT_EQ(seen.data[0], 0xAA);
  EXPECT_EQ(seen.data[1], 0xBB);
  EXPECT_FALSE(read_datagram(peer_.get(), 0).has_value());  // the invalid ones never left
}

TEST_F(SocketCanBusTest, SendBurstWritesEveryFrameInOrderAsItsOwnDatagram) {
  auto bus = make_bus(SystemClock::instance());
  std::vector<CanFrame> group;
  for (std::uint32_t id : {3U, 1U, 2U}) {
    // spec "Position": 06 02 01 00 3C 00 00 00, to three hands
    group.push_back(test::to_can_frame(protocol::make_write(id, protocol::reg::kPosition, 60)));
  }
  const auto taken = bus->send_burst(group);
  ASSERT_TRUE(taken.ok());
  EXPECT_EQ(taken.value(), 3u);
  for (std::uint32_t id : {3U, 1U, 2U}) {
    const auto datagram = read_datagram(peer_.get());
    ASSERT_TRUE(datagram.has_value());
    ASSERT_EQ(datagram->size(), sizeof(can_frame));
    can_frame seen{};
    std::memcpy(&seen, datagram->data(), sizeof seen);
    EXPECT_EQ(seen.can_id, id);
    EXPECT_EQ(std::vector<std::uint8_t>(seen.data, seen.data + 8),
              (std::vector<std::uint8_t>{0x06, 0x02, 0x01, 0x00, 0x3C, 0x00, 0x00, 0x00}));
  }
  EXPECT_EQ(bus->counters().frames_sent, 3u);
}

TEST_F(SocketCanBusTest, SendBurstStopsBeforeAnInvalidFrame) {
  auto bus = make_bus(SystemClock::instance());
  CanFrame valid;
  valid.id = 5;
  CanFrame invalid;
  invalid.id = 0x800;
  const std::vector<CanFrame> frames{valid, invalid, valid};
  const auto taken = bus->send_burst(frames);
  ASSERT_TRUE(taken.ok());
  EXPECT_EQ(taken.value(), 1u);
  EXPECT_EQ(bus->send_burst(std::span(frames).subspan(1)).error(), BusError::frame_invalid);
  EXPECT_TRUE(read_datagram(peer_.get()).has_value());
  EXPECT_FALSE(read_datagram(peer_.get(), 0).has_value()) << "only the first left";
}

TEST_F(SocketCanBusTest, ReceivesEveryFrameThePeerSends) {
  auto bus = make_bus(SystemClock::instance());
  const auto reply = protocol::make_write(2, protocol::reg::kRotation, 67);
  const auto payload = protocol::encode_payload(reply);
  write_frame(peer_.get(), make_can_frame(1, {1, 2, 3, 4, 5, 6, 7, 8}));
  write_frame(peer_.get(), make_can_frame(2, {payload.begin(), payload.end()}));
  write_frame(peer_.get(), make_can_frame(0xFF, {9}));

  const auto frames = test::receive_frames(*bus, 3);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[0], (CanFrame{1, 8, {1, 2, 3, 4, 5, 6, 7, 8}}));
  EXPECT_EQ(frames[1], test::to_can_frame(reply));
  EXPECT_EQ(frames[2], (CanFrame{0xFF, 1, {9}}));
  EXPECT_EQ(bus->counters().frames_received, 3u);
}

TEST_F(SocketCanBusTest, ReceiveTimesAreTheKernelsTimestampsWhenAskedFor) {
  SocketCanOptions options;
  options.receive_timestamps = true;
  auto bus = make_bus(SystemClock::instance(), options);
  const WallTime before = std::chrono::system_clock::now();
  write_frame(peer_.get(), make_can_frame(1, {1, 2, 3, 4, 5, 6, 7, 8}));
  write_frame(peer_.get(), make_can_frame(2, {1, 2, 3, 4, 5, 6, 7, 8}));
  std::vector<CanFrame> frames;
  std::vector<WallTime> times;
  const auto until = std::chrono::steady_clock::now() + test::kBusDeadline;
  while (frames.size() < 2 && std::chrono::steady_clock::now() < until) {
    (void)bus->receive(frames, test::kBusSlice);
    times.insert(times.end(), bus->receive_times().begin(), bus->receive_times().end());
  }
  const WallTime after = std::chrono::system_clock::now();
  ASSERT_EQ(frames.size(), 2u);
  ASSERT_EQ(times.size(), 2u);  // one per frame, in their order
  EXPECT_GE(times[0], before);
  EXPECT_LE(times[0], times[1]);
  EXPECT_LE(times[1], after);
}

TEST_F(SocketCanBusTest, ReceiveTimesAreEmptyWithoutTheOption) {
  auto bus = make_bus(SystemClock::instance());
  write_frame(peer_.get(), make_can_frame(1, {1, 2, 3, 4, 5, 6, 7, 8}));
  std::vector<CanFrame> frames;
  const auto until = std::chrono::steady_clock::now() + test::kBusDeadline;
  while (frames.empty() && std::chrono::steady_clock::now() < until) {
    (void)bus->receive(frames, test::kBusSlice);
  }
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_TRUE(bus->receive_times().empty());
}

TEST_F(SocketCanBusTest, IgnoresFramesNoDh3HandSends) {
  // The kernel filter keeps these off a real CAN socket; the user-space check
  // behind it is what this test sees.
  auto bus = make_bus(SystemClock::instance());
  write_frame(peer_.get(), make_can_frame(CAN_EFF_FLAG | 1, {1}));  // extended id
  write_frame(peer_.get(), make_can_frame(CAN_RTR_FLAG | 1, {}));   // remote request
  write_frame(peer_.get(), make_can_frame(0x100, {1}));             // above the hand range
  can_frame too_long = make_can_frame(1, {1});
  too_long.len = 9;
  write_frame(peer_.get(), too_long);
  const std::uint8_t runt[10] = {};
  write_datagram(peer_.get(), runt, sizeof runt);  // not a struct can_frame
  write_frame(peer_.get(), make_can_frame(3, {3, 3}));

  const auto frames = test::receive_frames(*bus, 1);
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0], (CanFrame{3, 2, {3, 3}}));
  EXPECT_EQ(bus->counters().frames_ignored, 5u);
}

TEST_F(SocketCanBusTest, ErrorFramesAreCountedNotDelivered) {
  auto bus = make_bus(SystemClock::instance());
  can_frame bus_off = make_can_frame(CAN_ERR_FLAG | CAN_ERR_BUSOFF, {0, 0, 0, 0, 0, 0, 0, 0});
  bus_off.len = CAN_ERR_DLC;
  write_frame(peer_.get(), bus_off);
  write_frame(peer_.get(), make_can_frame(4, {4}));

  const auto frames = test::receive_frames(*bus, 1);
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].id, 4u);
  EXPECT_EQ(bus->counters().error_frames, 1u);
  EXPECT_EQ(bus->link_state(), LinkState::up);
}

struct ErrorFrameCase {
  std::uint32_t classes;
  std::uint8_t controller_status;
  std::vector<ErrorFrameKind> kinds;
};

TEST(SocketCanErrorFrames, AreClassifiedByWhatTheControllerReports) {
  using K = ErrorFrameKind;
  const std::vector<ErrorFrameCase> cases{
      {CAN_ERR_BUSOFF, 0, {K::bus_off}},
      {CAN_ERR_RESTARTED, 0, {K::restarted}},
      {CAN_ERR_TX_TIMEOUT, 0, {K::tx_timeout}},
      {CAN_ERR_LOSTARB, 0, {K::lost_arbitration}},
      {CAN_ERR_PROT, 0, {K::protocol_violation}},
      {CAN_ERR_TRX, 0, {K::transceiver}},
      {CAN_ERR_ACK, 0, {K::no_ack}},
      {CAN_ERR_BUSERROR, 0, {K::bus_error}},
      {CAN_ERR_CRTL, CAN_ERR_CRTL_RX_OVERFLOW, {K::controller_overflow}},
      {CAN_ERR_CRTL, CAN_ERR_CRTL_TX_OVERFLOW, {K::controller_overflow}},
      {CAN_ERR_CRTL, CAN_ERR_CRTL_RX_WARNING, {K::error_warning}},
      {CAN_ERR_CRTL, CAN_ERR_CRTL_TX_WARNING, {K::error_warning}},
      {CAN_ERR_CRTL, CAN_ERR_CRTL_RX_PASSIVE, {K::error_passive}},
      {CAN_ERR_CRTL, CAN_ERR_CRTL_TX_PASSIVE, {K::error_passive}},
      {CAN_ERR_CRTL, CAN_ERR_CRTL_ACTIVE, {K::error_active}},
      {CAN_ERR_CRTL, 0, {}},  // unspecified controller problem: no kind to name
      {CAN_ERR_BUSOFF | CAN_ERR_CRTL, CAN_ERR_CRTL_TX_PASSIVE, {K::bus_off, K::error_passive}},
      {CAN_ERR_ACK | CAN_ERR_BUSERROR, 0, {K::no_ack, K::bus_error}},
  };
  for (const auto& c : cases) {
    std::uint8_t data[8] = {};
    data[1] = c.controller_status;
    // The controller-status byte means nothing without CAN_ERR_CRTL.
    const auto kinds = classify_error_frame(c.classes, data);
    std::bitset<kErrorFrameKinds> expected;
    for (auto kind : c.kinds) expected.set(static_cast<std::size_t>(kind));
    EXPECT_EQ(kinds, expected) << "classes 0x" << std::hex << c.classes << " status 0x"
                               << int{c.controller_status};
  }
  std::uint8_t passive[8] = {0, CAN_ERR_CRTL_RX_PASSIVE};
  EXPECT_FALSE(classify_error_frame(CAN_ERR_ACK, passive)
                   .test(static_cast<std::size_t>(ErrorFrameKind::error_passive)));
}

TEST_F(SocketCanBusTest, BusOffTakesTheLinkDownUntilTheControllerRestarts) {
  auto bus = make_bus(SystemClock::instance());
  can_frame bus_off = make_can_frame(CAN_ERR_FLAG | CAN_ERR_BUSOFF, {0, 0, 0, 0, 0, 0, 0, 0});
  write_frame(peer_.get(), bus_off);
  ASSERT_TRUE(test::wait_for_link(*bus, LinkState::down));
  EXPECT_TRUE(bus->diagnostics().bus_off);
  EXPECT_EQ(bus->send(CanFrame{}).error(), BusError::link_down);
  EXPECT_FALSE(read_datagram(peer_.get(), 0).has_value()) << "a frame went out while bus-off";
  std::vector<CanFrame> frames;
  EXPECT_EQ(bus->receive(frames, 0ms).error(), BusError::link_down);
  EXPECT_EQ(opens_, 1) << "bus-off is the controller's to end, not a reason to reopen";

  write_frame(peer_.get(),
              make_can_frame(CAN_ERR_FLAG | CAN_ERR_RESTARTED, {0, 0, 0, 0, 0, 0, 0, 0}));
  ASSERT_TRUE(test::wait_for_link(*bus, LinkState::up));
  EXPECT_FALSE(bus->diagnostics().bus_off);
  EXPECT_TRUE(bus->send(CanFrame{}).ok());
  const auto seen = bus->diagnostics();
  EXPECT_TRUE(seen.sees_controller);
  EXPECT_EQ(seen.error_frames[static_cast<std::size_t>(ErrorFrameKind::bus_off)], 1u);
  EXPECT_EQ(seen.error_frames[static_cast<std::size_t>(ErrorFrameKind::restarted)], 1u);
}

TEST_F(SocketCanBusTest, AFrameArrivingWhileBusOffEndsIt) {
  // The restart report can be lost (a full queue); frames prove the controller is back.
  auto bus = make_bus(SystemClock::instance());
  write_frame(peer_.get(), make_can_frame(CAN_ERR_FLAG | CAN_ERR_BUSOFF, {0, 0, 0, 0, 0, 0, 0, 0}));
  ASSERT_TRUE(test::wait_for_link(*bus, LinkState::down));
  write_frame(peer_.get(), make_can_frame(3, {3}));
  std::vector<CanFrame> frames;
  ASSERT_TRUE(test::wait_for_link(*bus, LinkState::up, &frames));
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].id, 3u);
}

TEST_F(SocketCanBusTest, WakeEndsAWaitingReceive) {
  auto bus = make_bus(SystemClock::instance());
  auto waiting = std::async(std::launch::async, [&bus] {
    std::vector<CanFrame> frames;
    return bus->receive(frames, std::chrono::minutes(2)).ok() && frames.empty();
  });
  // The waker cannot know when receive() starts polling; wake until it returns.
  const auto until = std::chrono::steady_clock::now() + 10s;
  while (waiting.wait_for(10ms) != std::future_status::ready &&
         std::chrono::steady_clock::now() < until) {
    bus->wake();
  }
  ASSERT_EQ(waiting.wait_for(0s), std::future_status::ready) << "wake() did not end receive()";
  EXPECT_TRUE(waiting.get());
}

TEST_F(SocketCanBusTest, WakeBeforeReceiveMakesTheNextReceiveReturn) {
  auto bus = make_bus(SystemClock::instance());
  bus->wake();
  auto waiting = std::async(std::launch::async, [&bus] {
    std::vector<CanFrame> frames;
    return bus->receive(frames, std::chrono::minutes(2)).ok();
  });
  ASSERT_EQ(waiting.wait_for(10s), std::future_status::ready) << "a pending wake() was lost";
  EXPECT_TRUE(waiting.get());
}

TEST_F(SocketCanBusTest, PeerClosingIsLinkDown) {
  auto bus = make_bus(fake_clock_);
  write_frame(peer_.get(), make_can_frame(1, {1}));
  peer_.reset();

  // The frame sent before the close still arrives; then the link is down.
  std::vector<CanFrame> frames;
  const auto until = std::chrono::steady_clock::now() + 10s;
  Result<void, BusError> last;
  while (std::chrono::steady_clock::now() < until) {
    last = bus->receive(frames, 20ms);
    if (!last.ok()) break;
  }
  ASSERT_FALSE(last.ok());
  EXPECT_EQ(last.error(), BusError::link_down);
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].id, 1u);
  EXPECT_EQ(bus->link_state(), LinkState::down);
  EXPECT_EQ(bus->send(CanFrame{}).error(), BusError::link_down);
  EXPECT_EQ(bus->counters().link_drops, 1u);
}

TEST_F(SocketCanBusTest, SendToAClosedPeerIsLinkDown) {
  auto bus = make_bus(fake_clock_);
  peer_.reset();
  EXPECT_EQ(bus->send(CanFrame{}).error(), BusError::link_down);
  EXPECT_EQ(bus->link_state(), LinkState::down);
}

TEST_F(SocketCanBusTest, ReopensWithDoublingBackoffDuringReceive) {
  SocketCanOptions options;
  options.reconnect.initial_backoff = 100ms;
  options.reconnect.max_backoff = 400ms;
  auto bus = make_bus(fake_clock_, options);
  ASSERT_EQ(opens_, 1);
  refuse_opens_ = true;
  peer_.reset();
  std::vector<CanFrame> frames;
  ASSERT_TRUE(test::wait_for_link(*bus, LinkState::down));

  auto receive_once = [&] { return bus->receive(frames, 0ms); };
  // Retries come after 100, 200, 400, 400 ms of (fake) time, never before.
  for (const auto wait : {100ms, 200ms, 400ms, 400ms}) {
    const int before = opens_;
    fake_clock_.advance(wait - 1ms);
    EXPECT_EQ(receive_once().error(), BusError::link_down);
    EXPECT_EQ(opens_, before) << "retried before the backoff of " << wait.count() << " ms ran out";
    fake_clock_.advance(1ms);
    EXPECT_EQ(receive_once().error(), BusError::link_down);
    EXPECT_EQ(opens_, before + 1) << "no retry after " << wait.count() << " ms";
  }

  // The interface is back: the next retry opens it and frames flow again.
  refuse_opens_ = false;
  fake_clock_.advance(400ms);
  EXPECT_TRUE(receive_once().ok());
  EXPECT_EQ(bus->link_state(), LinkState::up);
  write_frame(peer_.get(), make_can_frame(9, {9}));
  const auto received = test::receive_frames(*bus, 1);
  ASSERT_EQ(received.size(), 1u);
  EXPECT_EQ(received[0].id, 9u);
  ASSERT_TRUE(bus->send(CanFrame{}).ok());
  EXPECT_TRUE(read_datagram(peer_.get()).has_value());
  EXPECT_EQ(bus->counters().open_attempts, static_cast<std::uint64_t>(opens_));
}

TEST_F(SocketCanBusTest, AFirstOpenThatFailsLeavesTheBusDownAndRetrying) {
  refuse_opens_ = true;
  auto bus = make_bus(fake_clock_);
  EXPECT_EQ(bus->link_state(), LinkState::down);
  std::vector<CanFrame> frames;
  EXPECT_EQ(bus->receive(frames, 0ms).error(), BusError::link_down);
  refuse_opens_ = false;
  fake_clock_.advance(std::chrono::seconds(1));
  EXPECT_TRUE(bus->receive(frames, 0ms).ok());
  EXPECT_EQ(bus->link_state(), LinkState::up);
}

// ---- the real kernel path ----

TEST(SocketCanKernel, OpeningWithoutCanSupportIsAClearError) {
  const std::string problem = kernel_can_support_problem();
  if (problem.empty()) GTEST_SKIP() << "this kernel has CAN support; nothing to refuse";
  auto opened = SocketCanBus::open("socketcan:can0", "can0", SystemClock::instance());
  ASSERT_FALSE(opened.ok());
  EXPECT_THAT(opened.error(), HasSubstr("kernel has no CAN support: socket(PF_CAN) failed"));
  auto socket = open_can_raw_socket("can0");
  ASSERT_FALSE(socket.ok());
  EXPECT_THAT(socket.error(), HasSubstr("kernel has no CAN support"));
}

}  // namespace
}  // namespace dh3::bus
