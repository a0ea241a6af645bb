// SocketCanBus on a real kernel's CAN stack (vcan): the receive filter, the
// interface going down and up, deleted and created again, error frames by
// kind with bus-off taking the link down, the kernel's receive-queue drops,
// and foreign traffic. Run inside user-mode Linux by tests/kernel/uml-run.sh.

#include <gtest/gtest.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <sys/socket.h>

#include <random>
#include <string>
#include <vector>

#include "dh3/bus/socketcan_bus.hpp"
#include "kernel/can_interfaces.hpp"
#include "dh3/protocol/codec.hpp"
#include "support/bus_wait.hpp"

namespace dh3::bus {
namespace {

using namespace std::chrono_literals;
using test::RawCanSocket;
using test::OwnVcan;

class SocketCanKernel : public ::testing::Test {
 protected:
  void SetUp() override {
    DH3_REQUIRE_KERNEL_CAN();
    ASSERT_TRUE(vcan_.ready()) << vcan_.why();
    SocketCanOptions options;
    options.reconnect.initial_backoff = 20ms;
    options.reconnect.max_backoff = 200ms;
    auto opened = SocketCanBus::open("socketcan:" + vcan_.name(), vcan_.name(),
                                     SystemClock::instance(), options);
    ASSERT_TRUE(opened.ok()) << opened.error();
    bus_ = std::move(opened.value());
    ASSERT_TRUE(test::wait_for_link(*bus_, LinkState::up));
    ASSERT_TRUE(hands_.valid()) << errno_text(errno);
  }

  /// What the bus receives until `id` arrives (which is included).
  std::vector<CanFrame> receive_through(std::uint32_t id) {
    return test::receive_until(*bus_, [id](const std::vector<CanFrame>& frames) {
      return !frames.empty() && frames.back().id == id;
    });
  }

  /// The bus sends to hand 5 and the other node sees exactly that frame.
  void expect_frames_flow_out() {
    const auto request = protocol::make_read(5, protocol::reg::kPosition);
    ASSERT_TRUE(bus_->send(test::to_can_frame(request)).ok());
    const auto seen = hands_.receive();
    ASSERT_TRUE(seen.has_value()) << "the frame the bus sent never reached the interface";
    EXPECT_EQ(seen->can_id, 5u);
    EXPECT_EQ(seen->len, 8);
    const auto payload = protocol::encode_payload(request);
    EXPECT_TRUE(std::equal(payload.begin(), payload.end(), seen->data));
  }

  void inject_error_frame(std::uint32_t classes, std::uint8_t controller_status = 0) {
    std::vector<std::uint8_t> data(CAN_ERR_DLC, 0);
    data[1] = controller_status;
    ASSERT_TRUE(hands_.send(CAN_ERR_FLAG | classes, data));
  }

  std::uint64_t error_count(ErrorFrameKind kind) const {
    return bus_->diagnostics().error_frames[static_cast<std::size_t>(kind)];
  }

  OwnVcan vcan_{"dh3vcan"};
  std::unique_ptr<SocketCanBus> bus_;
  RawCanSocket hands_{vcan_.name()};
};

TEST_F(SocketCanKernel, KernelFilterPassesOnlyStandardDataFramesWithIds0To255) {
  // Every frame here but ids 0, 0x80 and 0xFF is one no DH-3 hand sends.
  ASSERT_TRUE(hands_.send(0x100, {1}));
  ASSERT_TRUE(hands_.send(0x7FF, {1}));
  ASSERT_TRUE(hands_.send(0x000, {0, 0, 0, 0, 0, 0, 0, 0}));
  ASSERT_TRUE(hands_.send(CAN_EFF_FLAG | 0x05, {1}));
  ASSERT_TRUE(hands_.send(CAN_EFF_FLAG | 0x1FFFFFFF, {1}));
  ASSERT_TRUE(hands_.send(CAN_RTR_FLAG | 0x05, {}));
  ASSERT_TRUE(hands_.send(0x080, {0x80}));
  ASSERT_TRUE(hands_.send(0x123, {1}));
  ASSERT_TRUE(hands_.send(0x0FF, {0xFF, 1}));

  const auto frames = receive_through(0xFF);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[0], (CanFrame{0x00, 8, {}}));
  EXPECT_EQ(frames[1], (CanFrame{0x80, 1, {0x80}}));
  EXPECT_EQ(frames[2], (CanFrame{0xFF, 2, {0xFF, 1}}));
  // The kernel dropped the rest: none reached user space to be ignored there.
  EXPECT_EQ(bus_->diagnostics().frames_ignored, 0u);
  EXPECT_EQ(bus_->counters().frames_received, 3u);
  expect_frames_flow_out();
}

TEST_F(SocketCanKernel, InterfaceDownAndUpTakesTheLinkDownAndBringsItBack) {
  expect_frames_flow_out();
  ASSERT_TRUE(vcan_.set_up(false));
  EXPECT_TRUE(test::wait_for_link(*bus_, LinkState::down));
  EXPECT_EQ(bus_->send(test::to_can_frame(protocol::make_read(5, protocol::reg::kPosition)))
                .error(),
            BusError::link_down);
  ASSERT_TRUE(vcan_.set_up(true));
  EXPECT_TRUE(test::wait_for_link(*bus_, LinkState::up));
  // The other node's socket held ENETDOWN too; RawCanSocket consumes it.
  expect_frames_flow_out();
  ASSERT_TRUE(hands_.send(7, {7}));
  const auto frames = receive_through(7);
  ASSERT_FALSE(frames.empty());
  EXPECT_EQ(frames.back(), (CanFrame{7, 1, {7}}));
  EXPECT_EQ(bus_->counters().link_drops, 1u);
}

TEST_F(SocketCanKernel, InterfaceDeletedAndCreatedAgainIsReopened) {
  expect_frames_flow_out();
  ASSERT_TRUE(vcan_.remove());
  EXPECT_TRUE(test::wait_for_link(*bus_, LinkState::down));
  // The bus keeps retrying a name that does not exist...
  const auto attempts = bus_->counters().open_attempts;
  test::receive_until(*bus_, [&](const auto&) { return bus_->counters().open_attempts > attempts + 1; });
  EXPECT_GT(bus_->counters().open_attempts, attempts + 1);
  EXPECT_EQ(bus_->link_state(), LinkState::down);
  // ...and opens the new interface of that name once it is there and up.
  ASSERT_TRUE(vcan_.create());
  EXPECT_TRUE(test::wait_for_link(*bus_, LinkState::up));
  RawCanSocket hands_again(vcan_.name());
  ASSERT_TRUE(hands_again.valid());
  ASSERT_TRUE(bus_->send(test::to_can_frame(protocol::make_read(9, protocol::reg::kPosition))).ok());
  const auto seen = hands_again.receive();
  ASSERT_TRUE(seen.has_value());
  EXPECT_EQ(seen->can_id, 9u);
  ASSERT_TRUE(hands_again.send(9, {9}));
  const auto frames = receive_through(9);
  ASSERT_FALSE(frames.empty());
  EXPECT_EQ(frames.back(), (CanFrame{9, 1, {9}}));
}

TEST_F(SocketCanKernel, ErrorFramesAreCountedByKindAndBusOffTakesTheLinkDownUntilRestart) {
  inject_error_frame(CAN_ERR_CRTL, CAN_ERR_CRTL_RX_WARNING);
  inject_error_frame(CAN_ERR_CRTL, CAN_ERR_CRTL_TX_PASSIVE);
  inject_error_frame(CAN_ERR_ACK);
  ASSERT_TRUE(hands_.send(1, {1}));
  const auto before = receive_through(1);
  ASSERT_EQ(before.size(), 1u) << "error frames must not reach the hand layer";
  EXPECT_EQ(error_count(ErrorFrameKind::error_warning), 1u);
  EXPECT_EQ(error_count(ErrorFrameKind::error_passive), 1u);
  EXPECT_EQ(error_count(ErrorFrameKind::no_ack), 1u);
  EXPECT_EQ(bus_->link_state(), LinkState::up);

  inject_error_frame(CAN_ERR_BUSOFF);
  EXPECT_TRUE(test::wait_for_link(*bus_, LinkState::down));
  EXPECT_TRUE(bus_->diagnostics().bus_off);
  EXPECT_EQ(error_count(ErrorFrameKind::bus_off), 1u);
  const auto probe = test::to_can_frame(protocol::make_read(5, protocol::reg::kPosition));
  EXPECT_EQ(bus_->send(probe).error(), BusError::link_down);
  std::vector<CanFrame> none;
  EXPECT_EQ(bus_->receive(none, 50ms).error(), BusError::link_down);

  inject_error_frame(CAN_ERR_RESTARTED);
  EXPECT_TRUE(test::wait_for_link(*bus_, LinkState::up));
  EXPECT_FALSE(bus_->diagnostics().bus_off);
  EXPECT_EQ(error_count(ErrorFrameKind::restarted), 1u);
  expect_frames_flow_out();
}

TEST_F(SocketCanKernel, FramesTheKernelDropsForAFullReceiveQueueAreCounted) {
  // Nobody reads the bus while another node sends far more than its socket's
  // receive buffer holds (about 200 KiB, a few hundred frames).
  constexpr int kSent = 5000;
  int sent = 0;
  for (int i = 0; i < kSent; ++i) sent += hands_.send(0x01, {1, 2, 3, 4, 5, 6, 7, 8}) ? 1 : 0;
  ASSERT_GT(sent, 1000);
  std::uint64_t received = 0;
  auto drain = [&] {
    std::vector<CanFrame> frames;
    for (int idle_rounds = 0; idle_rounds < 5;) {
      frames.clear();
      ASSERT_TRUE(bus_->receive(frames, 100ms).ok());
      received += frames.size();
      idle_rounds = frames.empty() ? idle_rounds + 1 : 0;
    }
  };
  drain();
  // The kernel tells the drop count with the next frame it queues.
  ASSERT_TRUE(hands_.send(0x02, {2}));
  drain();
  const auto drops = bus_->diagnostics().rx_overflow_drops;
  EXPECT_GT(drops, 0u) << "received " << received << " of " << sent + 1;
  EXPECT_GT(received, 1u);
  EXPECT_LE(received + drops, static_cast<std::uint64_t>(sent) + 1);
}

TEST_F(SocketCanKernel, ForeignTrafficNeverReachesTheServiceAndHandFramesStillDo) {
  // What cangen would put on a shared bus: random ids, extended frames, RTR,
  // every length; only standard data frames with ids 0-255 may come through.
  std::mt19937 random(12345);
  std::uniform_int_distribution<std::uint32_t> standard_id(0, CAN_SFF_MASK);
  std::uniform_int_distribution<std::uint32_t> extended_id(0, CAN_EFF_MASK);
  std::uniform_int_distribution<int> length(0, 8), kind(0, 3);
  std::vector<CanFrame> expected;
  for (int i = 0; i < 400; ++i) {
    std::vector<std::uint8_t> data(static_cast<std::size_t>(length(random)), 0xA5);
    std::uint32_t id = 0;
    switch (kind(random)) {
      case 0: id = CAN_EFF_FLAG | extended_id(random); break;
      case 1: id = CAN_RTR_FLAG | standard_id(random); data.clear(); break;
      default: id = standard_id(random); break;
    }
    ASSERT_TRUE(hands_.send(id, data));
    if ((id & (CAN_EFF_FLAG | CAN_RTR_FLAG)) == 0 && id <= 0xFF) {
      CanFrame frame{id, static_cast<std::uint8_t>(data.size()), {}};
      std::copy(data.begin(), data.end(), frame.data.begin());
      expected.push_back(frame);
    }
  }
  ASSERT_TRUE(hands_.send(0x42, {0x42}));
  expected.push_back(CanFrame{0x42, 1, {0x42}});
  const auto frames = test::receive_until(*bus_, [&](const auto& got) {
    return got.size() >= expected.size();
  });
  EXPECT_EQ(frames, expected);
  EXPECT_EQ(bus_->diagnostics().frames_ignored, 0u);
  expect_frames_flow_out();
}

}  // namespace
}  // namespace dh3::bus
