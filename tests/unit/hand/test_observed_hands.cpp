// A standby's warm state: ObservedHands reads the hands' state from the frames
// another service's scheduler and the hands put on the bus, and BusFence says
// when that service has gone quiet there. Every test runs on a FakeClock.

#include <gtest/gtest.h>

#include <memory>
#include <optional>

#include "dh3/hand/bus_fence.hpp"
#include "dh3/hand/observed_hands.hpp"
#include "unit/hand/scheduler_harness.hpp"

namespace dh3::hand::test {
namespace {

/// What a second socket on the interface sees: every frame the scheduler's
/// bus took and every frame the hands sent back.
class TapBus final : public bus::Bus {
 public:
  TapBus(std::unique_ptr<bus::Bus> inner, const Clock& clock, ObservedHands& watcher)
      : inner_(std::move(inner)), clock_(clock), watcher_(watcher) {}
  const std::string& spec() const override { return inner_->spec(); }
  Result<void, bus::BusError> send(const bus::CanFrame& frame) override {
    auto sent = inner_->send(frame);
    if (sent) watcher_.on_frame(frame, clock_.now());
    return sent;
  }
  Result<void, bus::BusError> receive(std::vector<bus::CanFrame>& out, Duration timeout) override {
    const std::size_t before = out.size();
    auto received = inner_->receive(out, timeout);
    for (std::size_t i = before; i < out.size(); ++i) watcher_.on_frame(out[i], clock_.now());
    return received;
  }
  void wake() override { inner_->wake(); }
  bus::LinkState link_state() const override { return inner_->link_state(); }

 private:
  std::unique_ptr<bus::Bus> inner_;
  const Clock& clock_;
  ObservedHands& watcher_;
};

/// A primary's scheduler on simulated hands, watched from the side.
struct WatchedBus {
  explicit WatchedBus(std::vector<sim::SimHandOptions> sim, const std::vector<std::uint8_t>& ids)
      : watcher(configs(ids), test_options().reply_timeout) {
    auto sim_bus = std::make_unique<sim::SimBus>("sim:test", std::move(sim), clock);
    primary = std::make_unique<BusScheduler>(
        "bus0", std::make_unique<TapBus>(std::move(sim_bus), clock, watcher), configs(ids),
        test_options(), clock, observer);
  }
  void run_for(Duration duration) {
    const TimePoint until = clock.now() + duration;
    while (clock.now() < until) {
      clock.advance(1ms);
      primary->step();
    }
  }
  std::optional<CommandResult> call(std::uint8_t id, Command command) {
    std::optional<CommandResult> result;
    primary->submit(id, command, [&](const CommandResult& r) { result = r; });
    const TimePoint until = clock.now() + 30s;
    while (!result && clock.now() < until) run_for(1ms);
    return result;
  }
  std::optional<HandState> primary_state(std::uint8_t id) const {
    for (const auto& s : primary->state()) {
      if (s.can_id == id) return s;
    }
    return std::nullopt;
  }

  FakeClock clock;
  RecordingObserver observer;
  ObservedHands watcher;
  std::unique_ptr<BusScheduler> primary;
};

/// The fields a standby takes over with.
void expect_same_hand(const HandState& primary, const HandState& standby) {
  EXPECT_EQ(standby.online, primary.online);
  EXPECT_EQ(standby.initialized, primary.initialized);
  EXPECT_EQ(standby.closing_force, primary.closing_force);
  EXPECT_EQ(standby.opening_force, primary.opening_force);
  EXPECT_EQ(standby.position, primary.position);
  EXPECT_EQ(standby.target_position, primary.target_position);
  EXPECT_EQ(to_string(standby.grip), to_string(primary.grip));
  EXPECT_EQ(standby.rotation, primary.rotation);
  EXPECT_EQ(standby.rotation_target, primary.rotation_target);
  EXPECT_EQ(to_string(standby.rotation_state), to_string(primary.rotation_state));
  EXPECT_EQ(standby.firmware_version, primary.firmware_version);
}

bool ok(const std::optional<CommandResult>& result) {
  return result && result->ok();
}

TEST(ObservedHands, KnowsWhatThePrimaryKnowsAfterItsCommands) {
  auto sim = sim_hands({1, 2});
  sim[0].object_position = 40;
  WatchedBus w(sim, {1, 2});
  w.run_for(1s);
  ASSERT_TRUE(ok(w.call(1, cmd(CommandKind::initialize))));
  ASSERT_TRUE(ok(w.call(2, cmd(CommandKind::initialize))));
  ASSERT_TRUE(ok(w.call(1, grasp(70))));
  ASSERT_TRUE(ok(w.call(2, cmd(CommandKind::set_opening_force, 35))));
  ASSERT_TRUE(ok(w.call(2, move(30))));
  ASSERT_TRUE(ok(w.call(2, cmd(CommandKind::rotate_to, 60))));
  w.run_for(2s);  // motions end, the poller reads everything again
  for (std::uint8_t id : {1, 2}) {
    SCOPED_TRACE(int(id));
    const auto primary = w.primary_state(id);
    const auto standby = w.watcher.state(id);
    ASSERT_TRUE(primary && standby);
    expect_same_hand(*primary, *standby);
    EXPECT_TRUE(standby->initialized);
  }
  EXPECT_EQ(to_string(w.watcher.state(1)->grip), to_string(GripState::grasped));
  EXPECT_EQ(w.watcher.state(1)->closing_force, 70);
  EXPECT_EQ(w.watcher.state(2)->position, 30);
  EXPECT_EQ(w.watcher.state(2)->rotation, 60);
}

TEST(ObservedHands, FollowsAMotionInProgressAndItsEnd) {
  WatchedBus w(sim_hands({1}), {1});
  w.run_for(1s);
  ASSERT_TRUE(ok(w.call(1, cmd(CommandKind::initialize))));
  ASSERT_TRUE(ok(w.call(1, move(10))));  // OK at the echo: the fingers still move
  ASSERT_TRUE(w.watcher.finger_motion(1).has_value());
  EXPECT_EQ(*w.watcher.finger_motion(1), 10);
  EXPECT_EQ(to_string(w.watcher.state(1)->grip), to_string(GripState::moving));
  w.run_for(2s);
  EXPECT_FALSE(w.watcher.finger_motion(1).has_value());
  expect_same_hand(*w.primary_state(1), *w.watcher.state(1));
}

bus::CanFrame frame_of(const protocol::Message& message) {
  bus::CanFrame frame;
  frame.id = message.hand_id;
  frame.data = protocol::encode_payload(message);
  return frame;
}

TEST(ObservedHands, AWriteIsInFlightUntilItsEchoIsSeen) {
  ObservedHands watcher(configs({1}), 100ms);
  const TimePoint t0 = TimePoint{} + 1h;
  const auto write = protocol::make_write(1, reg::kPosition, 60);
  EXPECT_EQ(watcher.on_frame(frame_of(write), t0), FrameRole::request);
  ASSERT_EQ(watcher.writes(1).size(), 1u);
  EXPECT_FALSE(watcher.writes(1).back().echoed);
  EXPECT_EQ(watcher.state(1)->target_position, -1);  // not taken yet
  EXPECT_EQ(watcher.on_frame(frame_of(write), t0 + 3ms), FrameRole::reply);
  EXPECT_TRUE(watcher.writes(1).back().echoed);
  EXPECT_EQ(watcher.state(1)->target_position, 60);
  EXPECT_EQ(watcher.requests_seen(), 1u);
}

TEST(ObservedHands, AnUnansweredRequestIsNotMistakenForTheNextRequestsReply) {
  ObservedHands watcher(configs({1}), 100ms);
  const TimePoint t0 = TimePoint{} + 1h;
  const auto write = protocol::make_write(1, reg::kPosition, 60);
  watcher.on_frame(frame_of(write), t0);  // the hand never echoes it
  // The same write again after the reply window is a re-send, not an echo.
  EXPECT_EQ(watcher.on_frame(frame_of(write), t0 + 150ms), FrameRole::request);
  EXPECT_EQ(watcher.writes(1).size(), 2u);
  EXPECT_FALSE(watcher.writes(1).front().echoed);
}

TEST(ObservedHands, TheHandsOwnInitFinishedFrameDoesNotBreakThePairing) {
  ObservedHands watcher(configs({1}), 100ms);
  const TimePoint t0 = TimePoint{} + 1h;
  watcher.on_frame(frame_of(protocol::make_read(1, reg::kPosition)), t0);
  // The hand's unsolicited "initialization finished" comes between.
  watcher.on_frame(frame_of(protocol::make_read(1, reg::kInitialize)), t0 + 1ms);
  // A position reply of 0 carries no value to tell it by: the pairing does.
  EXPECT_EQ(watcher.on_frame(frame_of(protocol::make_read(1, reg::kPosition)), t0 + 2ms),
            FrameRole::reply);
  EXPECT_EQ(watcher.state(1)->position, 0);
  // The service confirms; the hand says finished.
  watcher.on_frame(frame_of(protocol::make_read(1, reg::kInitialize)), t0 + 25ms);
  auto finished = protocol::make_read(1, reg::kInitialize);
  finished.data = 1;
  EXPECT_EQ(watcher.on_frame(frame_of(finished), t0 + 27ms), FrameRole::reply);
  EXPECT_TRUE(watcher.state(1)->initialized);
}

TEST(ObservedHands, AHandNotListedIsAddedWhenItAnswers) {
  ObservedHands watcher({}, 100ms);
  const TimePoint t0 = TimePoint{} + 1h;
  EXPECT_FALSE(watcher.state(9).has_value());
  watcher.on_frame(frame_of(protocol::make_read(9, reg::kFirmwareVersion)), t0);
  EXPECT_FALSE(watcher.state(9).has_value());  // a probe is no hand
  auto version = protocol::make_read(9, reg::kFirmwareVersion);
  version.data = 0x04010200;
  watcher.on_frame(frame_of(version), t0 + 2ms);
  ASSERT_TRUE(watcher.state(9).has_value());
  EXPECT_TRUE(watcher.state(9)->online);
  EXPECT_EQ(watcher.state(9)->firmware_version, 0x04010200);
}

TEST(ObservedHands, OtherTrafficIsNoRequest) {
  ObservedHands watcher(configs({1}), 100ms);
  bus::CanFrame other{0x300, 8, {}};
  EXPECT_EQ(watcher.on_frame(other, TimePoint{}), FrameRole::undecodable);
  bus::CanFrame bad_access{1, 8, {0x06, 0x02, 0x07, 0, 0, 0, 0, 0}};
  EXPECT_EQ(watcher.on_frame(bad_access, TimePoint{}), FrameRole::undecodable);
  EXPECT_EQ(watcher.requests_seen(), 0u);
}

TEST(BusFence, ABusThatStillCarriesRequestsIsNotClear) {
  const TimePoint t0 = TimePoint{} + 1h;
  BusFence fence(600ms, t0);
  EXPECT_FALSE(fence.clear(t0 + 599ms));  // never heard: wait the quiet time too
  EXPECT_TRUE(fence.clear(t0 + 600ms));
  fence.on_request(t0 + 700ms);
  EXPECT_FALSE(fence.clear(t0 + 1000ms));
  EXPECT_EQ(fence.clear_at(), t0 + 1300ms);
  fence.on_request(t0 + 650ms);  // seen late, older: changes nothing
  EXPECT_EQ(fence.clear_at(), t0 + 1300ms);
  EXPECT_TRUE(fence.clear(t0 + 1300ms));
}

TEST(BusFence, APrimaryThatPollsKeepsItsBusFenced) {
  // A primary frozen for DDS but still polling its idle hand on the bus.
  WatchedBus w(sim_hands({1}), {1});
  BusFence fence(test_options().poll_interval_idle + 100ms, w.clock.now());
  std::uint64_t seen = 0;
  for (int i = 0; i < 5000; ++i) {
    w.run_for(1ms);
    if (w.watcher.requests_seen() != seen) {
      seen = w.watcher.requests_seen();
      fence.on_request(w.clock.now());
    }
    if (i > 1000) {
      ASSERT_FALSE(fence.clear(w.clock.now())) << "clear " << i << " ms in while polled";
    }
  }
  // The primary's process ends (its loop steps no more): the bus goes quiet.
  const TimePoint stopped = w.clock.now();
  w.clock.advance(fence.quiet());
  EXPECT_TRUE(fence.clear(w.clock.now()));
  EXPECT_LE(fence.clear_at(), stopped + fence.quiet());
}

}  // namespace
}  // namespace dh3::hand::test
