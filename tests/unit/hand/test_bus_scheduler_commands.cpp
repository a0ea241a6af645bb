// Commands through the scheduler to simulated hands: every command ends in
// exactly one result, and that result is what the hand did.

#include <gtest/gtest.h>

#include "unit/hand/scheduler_harness.hpp"

namespace dh3::hand::test {
namespace {

TEST(BusSchedulerCommands, ConfiguredHandComesOnlineWithItsStateReadAfresh) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  ASSERT_TRUE(h.run_until([&] {
    auto s = h.state(1);
    return s && s->online && s->closing_force >= 0 && s->rotation >= 0;
  }));
  const auto s = *h.state(1);
  EXPECT_EQ(s.firmware_version, 0x04010200);
  EXPECT_EQ(s.closing_force, 50);
  EXPECT_EQ(s.opening_force, 50);
  EXPECT_FALSE(s.initialized);
  EXPECT_EQ(h.observer.events_of(EventKind::online, 1).size(), 1u);
}

TEST(BusSchedulerCommands, InitializeEnablesFeedbackAndEndsOnceTheHandFinished) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.run_until([&] { return h.state(1) && h.state(1)->online; });
  const auto result = h.call(1, cmd(CommandKind::initialize));
  ASSERT_TRUE(result);
  ASSERT_TRUE(result->ok()) << to_string(result->error());
  EXPECT_TRUE(h.state(1)->initialized);
  bool sim_initialized = false;
  h.sim_bus().with_hand(1, [&](sim::SimHand& hand) { sim_initialized = hand.initialized(); });
  EXPECT_TRUE(sim_initialized);
  EXPECT_EQ(h.observer.events_of(EventKind::initialized, 1).size(), 1u);
  // The document's two frames, in order: 0x0801 then 0x0802, each once.
  EXPECT_EQ(h.sent_to(1, reg::kInitFeedback).size(), 1u);
  const auto writes = h.sent_to(1, reg::kInitialize);
  std::size_t init_writes = 0;
  for (const auto& s : writes) init_writes += s.message.access == protocol::Access::write;
  EXPECT_EQ(init_writes, 1u);
}

TEST(BusSchedulerCommands, InitializationThatNeverFinishesFailsAtItsDeadline) {
  auto sim = sim_hands({1});
  sim[0].init_time = 1h;
  auto options = test_options();
  options.init_timeout = 1s;
  SchedulerHarness h(sim, configs({1}), options);
  h.run_until([&] { return h.state(1) && h.state(1)->online; });
  const auto result = h.call(1, cmd(CommandKind::initialize));
  ASSERT_TRUE(result);
  ASSERT_FALSE(result->ok());
  EXPECT_EQ(result->error(), CommandError::failed);
  EXPECT_EQ(h.observer.events_of(EventKind::init_failed, 1).size(), 1u);
  EXPECT_FALSE(h.state(1)->initialized);
}

TEST(BusSchedulerCommands, MotionBeforeInitializationIsRefusedWithoutReachingTheHand) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.run_until([&] { return h.state(1) && h.state(1)->online; });
  for (const Command& c :
       {move(30), grasp(40), cmd(CommandKind::rotate_to, 50), cmd(CommandKind::release, 90)}) {
    const auto result = h.call(1, c);
    ASSERT_TRUE(result);
    ASSERT_FALSE(result->ok());
    EXPECT_EQ(result->error(), CommandError::not_initialized) << to_string(c.kind);
  }
  for (const auto& s : h.sent_to(1)) {
    EXPECT_EQ(s.message.access, protocol::Access::read) << protocol::describe(s.message);
  }
}

TEST(BusSchedulerCommands, MoveSubmittedAtStartUpWaitsForTheInitializationFlagRead) {
  // The hand was initialized before the service started; a move submitted at
  // once must not be refused for lack of knowledge.
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.sim_bus().with_hand(1, [&](sim::SimHand& hand) {
    (void)hand.handle(protocol::make_write(1, reg::kInitialize, 0), h.clock.now());
  });
  h.clock.advance(500ms);  // the sim finishes initializing; the scheduler has not run yet
  const auto result = h.call(1, move(40));
  ASSERT_TRUE(result);
  EXPECT_TRUE(result->ok()) << to_string(result->error());
}

TEST(BusSchedulerCommands, MoveIsAnsweredOnEchoAndArrivalFollowsAsAnEvent) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.bring_up({1});
  const auto result = h.call(1, move(40));
  ASSERT_TRUE(result && result->ok());
  EXPECT_EQ(result->value().value, 40);
  EXPECT_EQ(h.state(1)->target_position, 40);
  ASSERT_TRUE(h.run_until([&] { return !h.observer.events_of(EventKind::arrived, 1).empty(); }));
  const auto arrived = h.observer.events_of(EventKind::arrived, 1).front();
  EXPECT_EQ(arrived.position, std::nullopt) << "not read yet; never where the motion started";
  EXPECT_EQ(arrived.target, 40);
  EXPECT_EQ(h.state(1)->grip, GripState::arrived);
  // Where the fingers stopped is read in the next frame.
  ASSERT_TRUE(h.run_until([&] { return h.state(1)->position == 40; }, 100ms));
}

TEST(BusSchedulerCommands, ForcesAndRotationAreWrittenAndKeptInTheState) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.bring_up({1});
  ASSERT_TRUE(h.call(1, cmd(CommandKind::set_closing_force, 70))->ok());
  ASSERT_TRUE(h.call(1, cmd(CommandKind::set_opening_force, 30))->ok());
  ASSERT_TRUE(h.call(1, cmd(CommandKind::rotate_to, 60))->ok());
  EXPECT_EQ(h.state(1)->closing_force, 70);
  EXPECT_EQ(h.state(1)->opening_force, 30);
  EXPECT_EQ(h.state(1)->rotation_target, 60);
  ASSERT_TRUE(
      h.run_until([&] { return !h.observer.events_of(EventKind::rotation_arrived, 1).empty(); }));
  EXPECT_EQ(h.state(1)->rotation_state, RotationState::arrived);
  // Where the rotation stopped is read in the next frame.
  ASSERT_TRUE(h.run_until([&] { return h.state(1)->rotation == 60; }, 100ms));
  std::int32_t sim_force = 0;
  h.sim_bus().with_hand(1, [&](sim::SimHand& hand) { sim_force = hand.closing_force(); });
  EXPECT_EQ(sim_force, 70);
}

TEST(BusSchedulerCommands, ReadRegisterReturnsTheHandsValue) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.bring_up({1});
  const auto version = h.call(1, read(reg::kFirmwareVersion));
  ASSERT_TRUE(version && version->ok());
  EXPECT_EQ(version->value().value, 0x04010200);
  const auto baud = h.call(1, read(reg::kBaudRate));
  ASSERT_TRUE(baud && baud->ok());
  EXPECT_EQ(baud->value().value, 0);
  const auto id = h.call(1, read(reg::kCanId));
  ASSERT_TRUE(id && id->ok());
  EXPECT_EQ(id->value().value, 1);
}

TEST(BusSchedulerCommands, OutOfRangeValuesAreRefusedAtOnceAndNeverSent) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.bring_up({1});
  const std::size_t frames_before = h.recorder().sent.size();
  const Command bad[] = {move(101),
                         move(-1),
                         cmd(CommandKind::rotate_to, 101),
                         cmd(CommandKind::set_closing_force, 19),
                         cmd(CommandKind::set_opening_force, 101),
                         grasp(10),
                         cmd(CommandKind::release, 200),
                         write(reg::kGripStatus, 1),
                         write(reg::kFirmwareVersion, 1),
                         read(protocol::Register{0x33, 0x01})};
  for (const Command& c : bad) {
    std::optional<CommandResult> result;
    // Completes on the caller's thread, before any step.
    h.scheduler->submit(1, c, [&](const CommandResult& r) { result = r; });
    ASSERT_TRUE(result) << to_string(c.kind) << " was not answered at once";
    ASSERT_FALSE(result->ok());
    EXPECT_EQ(result->error(), CommandError::invalid_argument);
  }
  h.run_for(10ms);
  for (std::size_t i = frames_before; i < h.recorder().sent.size(); ++i) {
    EXPECT_EQ(h.recorder().sent[i].message.access, protocol::Access::read)
        << "a write went out: " << protocol::describe(h.recorder().sent[i].message);
  }
}

TEST(BusSchedulerCommands, UnknownHandIsAnsweredAtOnce) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  std::optional<CommandResult> result;
  h.scheduler->submit(7, move(10), [&](const CommandResult& r) { result = r; });
  ASSERT_TRUE(result);
  EXPECT_EQ(result->error(), CommandError::unknown_hand);
}

TEST(BusSchedulerCommands, AdministrativeWritesNeedPermissionAndUseTheLongDeadline) {
  {
    SchedulerHarness h(sim_hands({1}), configs({1}));
    const auto refused = h.call(1, write(reg::kCanId, 5));
    ASSERT_TRUE(refused);
    EXPECT_EQ(refused->error(), CommandError::invalid_argument);
  }
  auto options = test_options();
  options.allow_admin = true;
  auto sim = sim_hands({1});
  sim[0].store_delay = 400ms;  // longer than reply_timeout: only the admin deadline fits
  SchedulerHarness h(sim, configs({1}), options);
  h.run_until([&] { return h.state(1) && h.state(1)->online; });
  const auto result = h.call(1, write(reg::kCanId, 5));
  ASSERT_TRUE(result);
  ASSERT_TRUE(result->ok()) << to_string(result->error());
  EXPECT_EQ(h.sent_to(1, reg::kCanId).size(), 1u) << "a CAN ID write must not be re-sent";
  std::uint8_t stored = 0;
  h.sim_bus().with_hand(1, [&](sim::SimHand& hand) { stored = hand.stored_id(); });
  EXPECT_EQ(stored, 5);
}

TEST(BusSchedulerCommands, IdZeroOnlyReadsOrSetsTheCanId) {
  SchedulerHarness h(sim_hands({2}), configs({2}));
  const auto id = h.call(0, read(reg::kCanId));
  ASSERT_TRUE(id);
  ASSERT_TRUE(id->ok()) << to_string(id->error());
  EXPECT_EQ(id->value().value, 2);
  std::optional<CommandResult> refused;
  h.scheduler->submit(0, move(10), [&](const CommandResult& r) { refused = r; });
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->error(), CommandError::invalid_argument);
}

TEST(BusSchedulerCommands, ANewMoveCancelsTheQueuedOneItSupersedes) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.bring_up({1});
  std::vector<std::optional<CommandResult>> results(3);
  auto submit = [&](int i) {
    h.scheduler->submit(1, move(10 + 30 * i), [&, i](const CommandResult& r) { results[i] = r; });
  };
  // The first goes out; the second waits for its turn and is superseded by
  // the third before it is sent. The first, already on the bus, stands.
  submit(0);
  ASSERT_TRUE(h.run_until([&] {
    return !h.sent_to(1, reg::kPosition).empty() &&
           h.sent_to(1, reg::kPosition).back().message.access == protocol::Access::write;
  }));
  submit(1);
  submit(2);
  ASSERT_TRUE(h.run_until([&] { return results[0] && results[1] && results[2]; }));
  EXPECT_TRUE(results[0]->ok());
  ASSERT_FALSE(results[1]->ok());
  EXPECT_EQ(results[1]->error(), CommandError::cancelled);
  EXPECT_TRUE(results[2]->ok());
  EXPECT_EQ(h.state(1)->target_position, 70);
  EXPECT_TRUE(h.sent_to(1, reg::kPosition).size() >= 2u);
  for (const auto& s : h.sent_to(1, reg::kPosition)) {
    if (s.message.access == protocol::Access::write) {
      EXPECT_NE(s.message.data, 40);
    }
  }
}

TEST(BusSchedulerCommands, FullQueueAnswersBusy) {
  auto options = test_options();
  options.queue_capacity = 3;
  SchedulerHarness h(sim_hands({1}), configs({1}), options);
  h.bring_up({1});
  int busy = 0;
  int completed = 0;
  for (int i = 0; i < 6; ++i) {
    h.scheduler->submit(1, read(reg::kPosition), [&](const CommandResult& r) {
      ++completed;
      if (!r.ok() && r.error() == CommandError::busy) ++busy;
    });
  }
  EXPECT_EQ(busy, 3);
  ASSERT_TRUE(h.run_until([&] { return completed == 6; }));
  EXPECT_EQ(busy, 3);
}

TEST(BusSchedulerCommands, StopHoldsTheCurrentPositionAndCancelsTheGrasp) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.bring_up({1});
  std::optional<CommandResult> grasp_result;
  h.scheduler->submit(1, grasp(50), [&](const CommandResult& r) { grasp_result = r; });
  // Let the fingers close a little, then stop.
  ASSERT_TRUE(h.run_until([&] { return h.sim_position(1) < 70; }));
  const auto stopped = h.call(1, cmd(CommandKind::stop));
  ASSERT_TRUE(stopped && stopped->ok());
  ASSERT_TRUE(grasp_result);
  EXPECT_EQ(grasp_result->error(), CommandError::cancelled);
  h.run_for(1s);
  const double final_position = h.sim_position(1);
  EXPECT_GT(final_position, 30.0) << "the fingers kept closing after stop";
  EXPECT_NEAR(final_position, stopped->value().value, 3.0);
}

TEST(BusSchedulerCommands, StopDuringAMotionReportsTheTargetOfTheMotionItEnded) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.bring_up({1});
  ASSERT_TRUE(h.call(1, move(10))->ok());
  ASSERT_TRUE(h.run_until([&] { return h.sim_position(1) < 70; }));
  const auto stopped = h.call(1, cmd(CommandKind::stop));
  ASSERT_TRUE(stopped && stopped->ok());
  ASSERT_TRUE(h.run_until([&] { return !h.observer.events_of(EventKind::arrived, 1).empty(); }));
  const auto arrived = h.observer.events_of(EventKind::arrived, 1);
  ASSERT_EQ(arrived.size(), 1u) << "one arrival: where the stop held the fingers";
  EXPECT_EQ(arrived[0].target, 10) << "the target the stop ended, not the held position";
  EXPECT_NE(arrived[0].message.find("stopped by STOP on the way to 10"), std::string::npos)
      << arrived[0].message;
  EXPECT_EQ(h.state(1)->target_position, stopped->value().value) << "the hand holds there";
}

TEST(BusSchedulerCommands, StopAtRestMovesNothingAndReportsNoArrival) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.bring_up({1});
  ASSERT_TRUE(h.call(1, move(40))->ok());
  ASSERT_TRUE(h.call(1, cmd(CommandKind::rotate_to, 30))->ok());
  ASSERT_TRUE(h.run_until([&] {
    return !h.observer.events_of(EventKind::arrived, 1).empty() &&
           !h.observer.events_of(EventKind::rotation_arrived, 1).empty();
  }));
  h.run_for(200ms);
  const TimePoint stop_at = h.clock.now();
  const auto stopped = h.call(1, cmd(CommandKind::stop));
  ASSERT_TRUE(stopped && stopped->ok());
  EXPECT_EQ(stopped->value().value, 40);
  h.run_for(1s);
  EXPECT_EQ(h.observer.events_of(EventKind::arrived, 1).size(), 1u);
  EXPECT_EQ(h.observer.events_of(EventKind::rotation_arrived, 1).size(), 1u);
  for (const auto& s : h.sent_to(1)) {
    if (s.at >= stop_at) {
      EXPECT_EQ(s.message.access, protocol::Access::read) << "nothing to hold";
    }
  }
  EXPECT_EQ(h.state(1)->target_position, 40);
  EXPECT_EQ(h.state(1)->rotation_target, 30);
}

TEST(BusSchedulerCommands, StopBeforeInitializationSucceedsWithoutMoving) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.run_until([&] { return h.state(1) && h.state(1)->online; });
  const auto result = h.call(1, cmd(CommandKind::stop));
  ASSERT_TRUE(result);
  EXPECT_TRUE(result->ok());
  for (const auto& s : h.sent_to(1)) EXPECT_EQ(s.message.access, protocol::Access::read);
}

TEST(BusSchedulerCommands, CommandTimeoutEndsACommandStillWaitingInTheQueue) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.bring_up({1});
  h.sim_bus().with_hand(1, [](sim::SimHand& hand) { hand.set_muted(true); });
  std::optional<CommandResult> first;
  std::optional<CommandResult> second;
  h.scheduler->submit(1, read(reg::kPosition), [&](const CommandResult& r) { first = r; });
  Command quick = read(reg::kRotation);
  quick.timeout = 50ms;
  h.scheduler->submit(1, quick, [&](const CommandResult& r) { second = r; });
  ASSERT_TRUE(h.run_until([&] { return first && second; }));
  EXPECT_EQ(second->error(), CommandError::timeout);
  EXPECT_EQ(first->error(), CommandError::timeout);
}

}  // namespace
}  // namespace dh3::hand::test
