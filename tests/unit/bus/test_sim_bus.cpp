// The in-process simulated bus with a FakeClock: routing by CAN ID, ID 0,
// several hands, line timing and arbitration, link loss, hands plugged in and
// out while running.

#include <gtest/gtest.h>

#include <future>
#include <span>
#include <vector>

#include "dh3/protocol/codec.hpp"
#include "dh3/protocol/registers.hpp"
#include "dh3/sim/sim_bus.hpp"

namespace dh3::bus {
namespace {

using namespace std::chrono_literals;
using protocol::make_read;
using protocol::make_write;
using protocol::Message;
namespace reg = protocol::reg;
using sim::SimBus;
using sim::SimBusOptions;

sim::SimHandOptions hand_options(std::uint8_t id) {
  sim::SimHandOptions options;
  options.id = id;
  options.init_time = 100ms;
  options.store_delay = 30ms;
  return options;
}

std::vector<sim::SimHandOptions> hands(std::initializer_list<std::uint8_t> ids) {
  std::vector<sim::SimHandOptions> result;
  for (const std::uint8_t id : ids) result.push_back(hand_options(id));
  return result;
}

CanFrame frame_of(const Message& message) {
  return CanFrame{message.hand_id, 8, protocol::encode_payload(message)};
}

Message message_of(const CanFrame& frame) {
  auto decoded = protocol::decode_payload(static_cast<std::uint8_t>(frame.id),
                                          std::span(frame.data.data(), frame.length));
  EXPECT_TRUE(decoded.ok());
  return decoded.ok() ? decoded.value() : Message{};
}

class SimBusTest : public ::testing::Test {
 protected:
  void open(std::vector<sim::SimHandOptions> hand_list, SimBusOptions options = {}) {
    bus_ = std::make_unique<SimBus>("sim:test", std::move(hand_list), clock_, options);
  }

  void send(const Message& message) { ASSERT_TRUE(bus_->send(frame_of(message)).ok()); }

  /// What is receivable now, without waiting.
  std::vector<Message> receive_now() {
    std::vector<CanFrame> frames;
    EXPECT_TRUE(bus_->receive(frames, Duration::zero()).ok());
    std::vector<Message> messages;
    for (const CanFrame& frame : frames) messages.push_back(message_of(frame));
    return messages;
  }

  /// Sends and returns the replies receivable at once.
  std::vector<Message> ask(const Message& message) {
    send(message);
    return receive_now();
  }

  FakeClock clock_;
  std::unique_ptr<SimBus> bus_;
};

TEST_F(SimBusTest, ARequestReachesOnlyTheHandWithThatId) {
  open(hands({1, 2, 3}));
  const std::vector<Message> replies = ask(make_write(2, reg::kClosingForce, 30));
  ASSERT_EQ(replies.size(), 1U);
  EXPECT_EQ(replies[0], make_write(2, reg::kClosingForce, 30));

  int closing_force[4] = {};
  for (const std::uint8_t id : {1, 2, 3}) {
    EXPECT_TRUE(
        bus_->with_hand(id, [&](sim::SimHand& hand) { closing_force[id] = hand.closing_force(); }));
  }
  EXPECT_EQ(closing_force[1], 50);
  EXPECT_EQ(closing_force[2], 30);
  EXPECT_EQ(closing_force[3], 50);
}

TEST_F(SimBusTest, SeveralHandsKeepTheirOwnState) {
  open(hands({1, 2, 3}));
  ask(make_write(1, reg::kOpeningForce, 21));
  ask(make_write(3, reg::kOpeningForce, 23));
  send(make_read(1, reg::kOpeningForce));
  send(make_read(2, reg::kOpeningForce));
  send(make_read(3, reg::kOpeningForce));
  const std::vector<Message> replies = receive_now();
  ASSERT_EQ(replies.size(), 3U);
  EXPECT_EQ(replies[0], (Message{1, reg::kOpeningForce, protocol::Access::read, 0, 21}));
  EXPECT_EQ(replies[1], (Message{2, reg::kOpeningForce, protocol::Access::read, 0, 50}));
  EXPECT_EQ(replies[2], (Message{3, reg::kOpeningForce, protocol::Access::read, 0, 23}));
}

TEST_F(SimBusTest, NobodyAnswersAnIdWithoutAHand) {
  open(hands({1}));
  EXPECT_TRUE(ask(make_read(9, reg::kFirmwareVersion)).empty());
  clock_.advance(1s);
  EXPECT_TRUE(receive_now().empty());
  EXPECT_EQ(bus_->frames_sent(), 1U);
  EXPECT_EQ(bus_->frames_delivered(), 0U);
}

TEST_F(SimBusTest, IdZeroReachesEveryHandButOnlyForTheCanIdRegister) {
  open(hands({1, 2, 3}));
  const std::vector<Message> replies = ask(make_read(0, reg::kCanId));
  ASSERT_EQ(replies.size(), 3U);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(replies[i].hand_id, 0);
    EXPECT_EQ(replies[i].data, static_cast<std::int32_t>(i + 1));
  }
  EXPECT_TRUE(ask(make_read(0, reg::kFirmwareVersion)).empty());
  EXPECT_TRUE(ask(make_write(0, reg::kPosition, 10)).empty());
}

TEST_F(SimBusTest, RepliesWaitForTheHandsReplyDelay) {
  std::vector<sim::SimHandOptions> list = hands({1, 2});
  list[0].reply_delay = 5ms;
  open(list);
  send(make_read(1, reg::kFirmwareVersion));
  send(make_read(2, reg::kFirmwareVersion));
  std::vector<Message> replies = receive_now();
  ASSERT_EQ(replies.size(), 1U);
  EXPECT_EQ(replies[0].hand_id, 2);
  clock_.advance(4ms);
  EXPECT_TRUE(receive_now().empty());
  clock_.advance(1ms);
  replies = receive_now();
  ASSERT_EQ(replies.size(), 1U);
  EXPECT_EQ(replies[0].hand_id, 1);
}

TEST_F(SimBusTest, TheInitializationFrameComesUnsolicited) {
  open(hands({1, 2}));
  ask(make_write(2, reg::kInitFeedback, 0));
  ask(make_write(2, reg::kInitialize, 0));
  clock_.advance(99ms);
  EXPECT_TRUE(receive_now().empty());
  clock_.advance(1ms);
  const std::vector<Message> frames = receive_now();
  ASSERT_EQ(frames.size(), 1U);
  EXPECT_EQ(frames[0], make_read(2, reg::kInitialize));
  EXPECT_EQ(ask(make_read(2, reg::kInitialize)).at(0).data, 1);
}

TEST_F(SimBusTest, AnIdleBusStillDeliversTheInitializationFrameLate) {
  open(hands({1}));
  ask(make_write(1, reg::kInitFeedback, 0));
  ask(make_write(1, reg::kInitialize, 0));
  clock_.advance(10s);  // nobody asked in between
  EXPECT_EQ(receive_now().size(), 1U);
}

TEST_F(SimBusTest, WithABitRateARequestAndItsReplyTakeTwoFrameTimes) {
  // 111 bits at 111 kbit/s: exactly 1 ms per frame.
  open(hands({1}), SimBusOptions{111'000, 111});
  EXPECT_TRUE(ask(make_read(1, reg::kFirmwareVersion)).empty());
  clock_.advance(1999us);
  EXPECT_TRUE(receive_now().empty());
  clock_.advance(1us);
  EXPECT_EQ(receive_now().size(), 1U);
}

TEST_F(SimBusTest, FramesShareTheLineAndTheLowestIdWinsArbitration) {
  open(hands({1, 2, 3}), SimBusOptions{111'000, 111});
  // Sent 3, 2, 1 at once. 3 takes the idle line (0-1 ms); then at each free
  // slot the lowest waiting ID goes: request 1 (1-2), reply 1 (2-3),
  // request 2 (3-4), reply 2 (4-5), reply 3 (5-6).
  send(make_read(3, reg::kFirmwareVersion));
  send(make_read(2, reg::kFirmwareVersion));
  send(make_read(1, reg::kFirmwareVersion));
  std::vector<std::pair<int, std::uint32_t>> arrivals;  // (ms, hand)
  for (int ms = 0; ms <= 8; ++ms) {
    for (const Message& reply : receive_now()) arrivals.emplace_back(ms, reply.hand_id);
    clock_.advance(1ms);
  }
  const std::vector<std::pair<int, std::uint32_t>> expected{{3, 1}, {5, 2}, {6, 3}};
  EXPECT_EQ(arrivals, expected);
}

TEST_F(SimBusTest, AFullTransmitQueueSaysWouldBlock) {
  open(hands({1}), SimBusOptions{111'000, 111, 2});
  send(make_read(1, reg::kFirmwareVersion));  // on the line
  send(make_read(1, reg::kFirmwareVersion));  // waiting
  send(make_read(1, reg::kFirmwareVersion));  // waiting
  const auto refused = bus_->send(frame_of(make_read(1, reg::kFirmwareVersion)));
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error(), BusError::would_block);
  clock_.advance(1ms);
  receive_now();
  EXPECT_TRUE(bus_->send(frame_of(make_read(1, reg::kFirmwareVersion))).ok());
}

TEST_F(SimBusTest, InvalidFramesAreRefused) {
  open(hands({1}));
  CanFrame too_high = frame_of(make_read(1, reg::kFirmwareVersion));
  too_high.id = 0x800;
  EXPECT_EQ(bus_->send(too_high).error(), BusError::frame_invalid);
  CanFrame too_long = frame_of(make_read(1, reg::kFirmwareVersion));
  too_long.length = 9;
  EXPECT_EQ(bus_->send(too_long).error(), BusError::frame_invalid);
}

TEST_F(SimBusTest, PayloadsTheHandCannotReadAreIgnored) {
  open(hands({1}));
  CanFrame bad_access = frame_of(make_read(1, reg::kFirmwareVersion));
  bad_access.data[2] = 0x07;
  ASSERT_TRUE(bus_->send(bad_access).ok());
  CanFrame short_frame = frame_of(make_read(1, reg::kFirmwareVersion));
  short_frame.length = 4;
  ASSERT_TRUE(bus_->send(short_frame).ok());
  EXPECT_TRUE(receive_now().empty());
  EXPECT_EQ(ask(make_read(1, reg::kFirmwareVersion)).size(), 1U);
}

TEST_F(SimBusTest, ALinkDownRefusesTrafficAndLosesFramesInFlight) {
  std::vector<sim::SimHandOptions> list = hands({1});
  list[0].reply_delay = 10ms;
  open(list);
  send(make_read(1, reg::kFirmwareVersion));
  bus_->set_link_up(false);
  EXPECT_EQ(bus_->link_state(), LinkState::down);
  EXPECT_EQ(bus_->send(frame_of(make_read(1, reg::kFirmwareVersion))).error(), BusError::link_down);
  std::vector<CanFrame> frames;
  EXPECT_EQ(bus_->receive(frames, Duration::zero()).error(), BusError::link_down);

  clock_.advance(20ms);
  bus_->set_link_up(true);
  EXPECT_EQ(bus_->link_state(), LinkState::up);
  EXPECT_TRUE(receive_now().empty()) << "the reply in flight was lost";
  EXPECT_EQ(ask(make_read(1, reg::kClosingForce)).size(), 0U);  // 10 ms reply delay
  clock_.advance(10ms);
  EXPECT_EQ(receive_now().size(), 1U);
}

TEST_F(SimBusTest, FramesThatCameDueWhileTheLinkWasDownAreLost) {
  open(hands({1}));
  ask(make_write(1, reg::kInitFeedback, 0));
  ask(make_write(1, reg::kInitialize, 0));
  bus_->set_link_up(false);
  clock_.advance(1s);
  bus_->set_link_up(true);
  EXPECT_TRUE(receive_now().empty());
  EXPECT_EQ(ask(make_read(1, reg::kInitialize)).at(0).data, 1) << "the hand itself went on";
}

TEST_F(SimBusTest, HandsCanBePluggedInAndOut) {
  open(hands({1}));
  EXPECT_TRUE(ask(make_read(7, reg::kFirmwareVersion)).empty());
  bus_->add_hand(hand_options(7));
  EXPECT_EQ(ask(make_read(7, reg::kFirmwareVersion)).size(), 1U);
  bus_->remove_hand(7);
  EXPECT_TRUE(ask(make_read(7, reg::kFirmwareVersion)).empty());
  EXPECT_FALSE(bus_->with_hand(7, [](sim::SimHand&) {}));
  EXPECT_EQ(ask(make_read(1, reg::kFirmwareVersion)).size(), 1U);
}

TEST_F(SimBusTest, ARebootedHandIsFoundUnderItsNewId) {
  open(hands({1}));
  ask(make_write(1, reg::kCanId, 5));
  clock_.advance(30ms);
  EXPECT_EQ(receive_now().size(), 1U) << "the CAN ID write is answered once stored";
  EXPECT_EQ(ask(make_read(1, reg::kCanId)).at(0).data, 5) << "stored, not active yet";
  EXPECT_TRUE(bus_->with_hand(1, [&](sim::SimHand& hand) { hand.reboot(clock_.now()); }));
  EXPECT_FALSE(bus_->with_hand(1, [](sim::SimHand&) {}));
  EXPECT_TRUE(ask(make_read(1, reg::kCanId)).empty());
  EXPECT_EQ(ask(make_read(5, reg::kCanId)).at(0).data, 5);
}

TEST_F(SimBusTest, InjectionsHappenAtTheCurrentTime) {
  open(hands({1}));
  ask(make_write(1, reg::kInitialize, 0));
  clock_.advance(100ms);
  bus_->with_hand(1, [](sim::SimHand& hand) { hand.place_object(50); });
  ask(make_write(1, reg::kPosition, 0));
  clock_.advance(1s);
  EXPECT_EQ(ask(make_read(1, reg::kGripStatus)).at(0).data, 3);
  clock_.advance(1s);
  bus_->with_hand(1, [](sim::SimHand& hand) { hand.drop_object(); });
  clock_.advance(100ms);  // 200 %/s: 20 % further
  double position = 0;
  bus_->with_hand(1, [&](sim::SimHand& hand) { position = hand.position(); });
  EXPECT_DOUBLE_EQ(position, 30.0) << "the drop happened now, not at the last request";
}

TEST_F(SimBusTest, WakeMakesAWaitingReceiveReturn) {
  open(hands({1}));
  auto waiting = std::async(std::launch::async, [&] {
    std::vector<CanFrame> frames;
    return bus_->receive(frames, std::chrono::hours(1)).ok();
  });
  bus_->wake();
  ASSERT_EQ(waiting.wait_for(10s), std::future_status::ready);
  EXPECT_TRUE(waiting.get());
}

TEST_F(SimBusTest, ALinkGoingDownWakesAWaitingReceive) {
  open(hands({1}));
  auto waiting = std::async(std::launch::async, [&] {
    std::vector<CanFrame> frames;
    return bus_->receive(frames, std::chrono::hours(1)).ok();
  });
  bus_->set_link_up(false);
  ASSERT_EQ(waiting.wait_for(10s), std::future_status::ready);
  EXPECT_FALSE(waiting.get());
}

TEST(SimBusRealTime, ReceiveWaitsForADelayedReply) {
  std::vector<sim::SimHandOptions> list = hands({1});
  list[0].reply_delay = 20ms;
  SimBus bus("sim:1", list, SystemClock::instance());
  ASSERT_TRUE(bus.send(frame_of(make_read(1, reg::kFirmwareVersion))).ok());
  std::vector<CanFrame> frames;
  // One call: it must wait for the reply rather than return empty.
  ASSERT_TRUE(bus.receive(frames, 10s).ok());
  ASSERT_EQ(frames.size(), 1U);
  EXPECT_EQ(message_of(frames[0]).data, 0x04010200);
}

TEST(SimBusRealTime, ReceiveWaitsForTheInitializationFrame) {
  std::vector<sim::SimHandOptions> list = hands({1});
  list[0].init_time = 30ms;
  SimBus bus("sim:1", list, SystemClock::instance());
  std::vector<CanFrame> frames;
  ASSERT_TRUE(bus.send(frame_of(make_write(1, reg::kInitFeedback, 0))).ok());
  ASSERT_TRUE(bus.send(frame_of(make_write(1, reg::kInitialize, 0))).ok());
  ASSERT_TRUE(bus.receive(frames, 10s).ok());
  ASSERT_EQ(frames.size(), 2U) << "the two echoes";
  frames.clear();
  ASSERT_TRUE(bus.receive(frames, 10s).ok());
  ASSERT_EQ(frames.size(), 1U);
  EXPECT_EQ(message_of(frames[0]), make_read(1, reg::kInitialize));
}

}  // namespace
}  // namespace dh3::bus
