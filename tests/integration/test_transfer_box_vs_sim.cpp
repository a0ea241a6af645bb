// The TCP transfer-box backend against the real dh3-sim process: frames go
// through a real socket to simulated hands and back, and link loss (the sim
// kicking its clients, the sim dying) is seen and recovered from.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <optional>
#include <string>

#include "dh3/bus/bus_spec.hpp"
#include "dh3/bus/transfer_box_bus.hpp"
#include "dh3/protocol/codec.hpp"
#include "support/bus_wait.hpp"
#include "support/process.hpp"

namespace dh3::bus {
namespace {

using namespace std::chrono_literals;
using protocol::make_read;
using protocol::make_write;
using protocol::Message;
namespace reg = protocol::reg;

/// dh3-sim with hands 1, 2, 3, fast enough for tests, and a bus connected to it.
class TransferBoxVsSim : public ::testing::Test {
 protected:
  void SetUp() override {
    sim_ = std::make_unique<test::Process>(
        DH3_SIM_PATH, std::vector<std::string>{"--listen", "127.0.0.1:0", "--hands", "1,2,3",
                                               "--init-time-ms", "50", "--speed", "1000"});
    ASSERT_TRUE(sim_->started()) << "cannot start " << DH3_SIM_PATH;
    const auto line = sim_->wait_for_line("listening ", 10s);
    ASSERT_TRUE(line.has_value()) << "dh3-sim did not say where it listens";
    address_ = line->substr(std::string("listening ").size());  // "127.0.0.1:PORT"

    OpenBusOptions options;
    options.transfer_box.reconnect.initial_backoff = 20ms;
    options.transfer_box.reconnect.max_backoff = 200ms;
    auto opened = open_bus("tcp:" + address_, SystemClock::instance(), options);
    ASSERT_TRUE(opened.ok()) << opened.error();
    bus_ = std::move(opened.value());
    ASSERT_TRUE(test::wait_for_link(*bus_, LinkState::up)) << "no connection to " << address_;
  }

  /// Sends `request` and returns the reply with the same (hand, register), per
  /// docs/protocol-notes.md reading 1; nullopt if none came within 10 s. Other frames
  /// received meanwhile are kept in `others_`.
  std::optional<Message> transact(const Message& request) {
    if (!bus_->send(test::to_can_frame(request)).ok()) return std::nullopt;
    std::optional<Message> reply;
    test::receive_until(*bus_, [&](const std::vector<CanFrame>& frames) {
      for (const CanFrame& frame : frames) {
        auto message = protocol::decode_payload(static_cast<std::uint8_t>(frame.id), frame.data);
        if (message && message->hand_id == request.hand_id && message->reg == request.reg) {
          reply = *message;
          return true;
        }
      }
      return false;
    });
    return reply;
  }

  /// Reads `r` of `hand` until it equals `want` (10 s).
  bool read_until(std::uint8_t hand, protocol::Register r, std::int32_t want) {
    const auto until = std::chrono::steady_clock::now() + 10s;
    while (std::chrono::steady_clock::now() < until) {
      const auto reply = transact(make_read(hand, r));
      if (reply && protocol::status_value(*reply) == want) return true;
    }
    return false;
  }

  std::unique_ptr<test::Process> sim_;
  std::string address_;
  std::unique_ptr<Bus> bus_;
};

TEST_F(TransferBoxVsSim, EachHandAnswersReadsUnderItsOwnId) {
  const auto version = transact(make_read(2, reg::kFirmwareVersion));
  ASSERT_TRUE(version.has_value());
  EXPECT_EQ(version->hand_id, 2);
  EXPECT_EQ(version->data, 0x04010200);  // the document's 00 02 01 04
  for (const std::uint8_t hand : {1, 3}) {
    const auto position = transact(make_read(hand, reg::kPosition));
    ASSERT_TRUE(position.has_value()) << "hand " << int{hand};
    EXPECT_EQ(position->data, 100) << "a hand starts fully open";
  }
}

TEST_F(TransferBoxVsSim, AnIdWithoutAHandStaysSilent) {
  ASSERT_TRUE(bus_->send(test::to_can_frame(make_read(4, reg::kPosition))).ok());
  // dh3-sim answers in order on one connection: once hand 3's reply is in,
  // a reply from hand 4 would have come before it.
  ASSERT_TRUE(bus_->send(test::to_can_frame(make_read(3, reg::kPosition))).ok());
  const std::vector<CanFrame> frames = test::receive_frames(*bus_, 1);
  ASSERT_FALSE(frames.empty());
  EXPECT_EQ(frames.front().id, 3u);
  for (const CanFrame& frame : frames) EXPECT_NE(frame.id, 4u);
}

TEST_F(TransferBoxVsSim, InitializeThenWritePositionAndReadItBack) {
  // spec "Initialize": write 0x0802, the echo comes at once, 0x0802 reads 1 when done.
  const auto echo = transact(make_write(1, reg::kInitialize, 0));
  ASSERT_TRUE(echo.has_value());
  EXPECT_EQ(echo->access, protocol::Access::write);
  ASSERT_TRUE(read_until(1, reg::kInitialize, 1)) << "hand 1 never finished initializing";

  const auto position_echo = transact(make_write(1, reg::kPosition, 30));
  ASSERT_TRUE(position_echo.has_value());
  EXPECT_EQ(position_echo->data, 30);
  ASSERT_TRUE(
      read_until(1, reg::kGripStatus, static_cast<std::int32_t>(protocol::GripStatus::arrived)))
      << "hand 1 never arrived";
  const auto position = transact(make_read(1, reg::kPosition));
  ASSERT_TRUE(position.has_value());
  EXPECT_EQ(position->data, 30);

  // The other hands did not move.
  const auto other = transact(make_read(2, reg::kPosition));
  ASSERT_TRUE(other.has_value());
  EXPECT_EQ(other->data, 100);

  // And the simulator agrees about its hand's true state.
  ASSERT_TRUE(sim_->write_line("state 1"));
  const auto state = sim_->wait_for_line("ok state 1", 10s);
  ASSERT_TRUE(state.has_value());
  EXPECT_THAT(*state, ::testing::HasSubstr("position=30"));
}

TEST_F(TransferBoxVsSim, ForceWritesAreEchoedAndReadBack) {
  const auto echo = transact(make_write(3, reg::kClosingForce, 30));
  ASSERT_TRUE(echo.has_value());
  EXPECT_EQ(echo->data, 30);
  const auto force = transact(make_read(3, reg::kClosingForce));
  ASSERT_TRUE(force.has_value());
  EXPECT_EQ(force->data, 30);
}

TEST_F(TransferBoxVsSim, ReconnectsAfterTheSimDropsTheConnection) {
  ASSERT_TRUE(transact(make_read(1, reg::kPosition)).has_value());
  ASSERT_TRUE(sim_->write_line("kick"));
  ASSERT_TRUE(sim_->wait_for_line("ok kick", 10s).has_value());
  ASSERT_TRUE(test::wait_for_link(*bus_, LinkState::down)) << "the drop went unnoticed";
  ASSERT_TRUE(test::wait_for_link(*bus_, LinkState::up)) << "no reconnect";
  const auto version = transact(make_read(1, reg::kFirmwareVersion));
  ASSERT_TRUE(version.has_value());
  EXPECT_EQ(version->data, 0x04010200);
  EXPECT_EQ(dynamic_cast<TransferBoxBus&>(*bus_).counters().link_drops, 1u);
}

TEST_F(TransferBoxVsSim, ASimThatDiesLeavesTheBusDownAndRetrying) {
  ASSERT_TRUE(sim_->send_signal(SIGKILL));
  ASSERT_TRUE(sim_->wait_exit(10s).has_value());
  ASSERT_TRUE(test::wait_for_link(*bus_, LinkState::down));
  auto& box = dynamic_cast<TransferBoxBus&>(*bus_);
  const auto attempts = box.counters().open_attempts;
  test::receive_until(*bus_,
                      [&](const auto&) { return box.counters().open_attempts >= attempts + 2; });
  EXPECT_GE(box.counters().open_attempts, attempts + 2);
  EXPECT_EQ(bus_->link_state(), LinkState::down);
  EXPECT_EQ(bus_->send(test::to_can_frame(make_read(1, reg::kPosition))).error(),
            BusError::link_down);
}

}  // namespace
}  // namespace dh3::bus
