// The states a user cares about, detected from what the hand reports: grasped,
// missed, dropped, arrived, rotation arrived and blocked, initialized (with the
// unsolicited frame), and faults. Each event carries the values that explain it.
// An event goes out on the status read that shows it; where the motion stopped
// is read in the next frame, so the event says it is not read yet, and a status
// sample with where the motion stopped follows.

#include <gtest/gtest.h>

#include <optional>
#include <string>

#include "unit/hand/scheduler_harness.hpp"

namespace dh3::hand::test {
namespace {

/// The first state of hand `id` published at or after `at` whose position
/// (rotation) is `value`.
std::optional<HandState> sample_at(const RecordingObserver& observer, std::uint8_t id, TimePoint at,
                                   std::int32_t value, bool rotation = false) {
  for (const HandState& state : observer.states) {
    if (state.can_id != id || state.updated_at < at) continue;
    if ((rotation ? state.rotation : state.position) == value) return state;
  }
  return std::nullopt;
}

TEST(BusSchedulerEvents, GraspOnAnObjectEndsGraspedWithWhereTheFingersStopped) {
  auto sim = sim_hands({1});
  sim[0].object_position = 35;
  SchedulerHarness h(sim, configs({1}));
  h.bring_up({1});
  const auto result = h.call(1, grasp(60));
  ASSERT_TRUE(result);
  ASSERT_TRUE(result->ok()) << to_string(result->error());
  EXPECT_EQ(result->value().grasp, GraspOutcome::grasped);
  EXPECT_EQ(result->value().value, 35);
  const auto grasped = h.observer.events_of(EventKind::grasped, 1);
  ASSERT_EQ(grasped.size(), 1u);
  EXPECT_EQ(grasped[0].value, 60) << "a grasp is explained by its force";
  EXPECT_EQ(grasped[0].target, 0);
  EXPECT_EQ(grasped[0].position, std::nullopt)
      << "not read yet, and never the position before the motion";
  const auto stopped = sample_at(h.observer, 1, grasped[0].time, 35);
  ASSERT_TRUE(stopped) << "a sample says where the fingers stopped";
  EXPECT_EQ(stopped->grip, GripState::grasped);
  EXPECT_LE(stopped->updated_at - grasped[0].time, 2 * test_options().command_interval);
  EXPECT_EQ(h.state(1)->grip, GripState::grasped);
  EXPECT_EQ(h.state(1)->closing_force, 60);
  EXPECT_TRUE(h.observer.events_of(EventKind::missed, 1).empty());
}

TEST(BusSchedulerEvents, GraspWithNothingThereEndsMissedAtTheClosedPosition) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.bring_up({1});
  const auto result = h.call(1, grasp(30));
  ASSERT_TRUE(result && result->ok());
  EXPECT_EQ(result->value().grasp, GraspOutcome::missed);
  EXPECT_EQ(result->value().value, 0);
  EXPECT_EQ(h.observer.events_of(EventKind::missed, 1).size(), 1u);
  EXPECT_EQ(h.state(1)->grip, GripState::missed);
}

TEST(BusSchedulerEvents, ObjectLostWithNoCommandIsADrop) {
  auto sim = sim_hands({1});
  sim[0].object_position = 50;
  SchedulerHarness h(sim, configs({1}));
  h.bring_up({1});
  ASSERT_EQ(h.call(1, grasp(40))->value().grasp, GraspOutcome::grasped);
  h.run_for(1s);
  EXPECT_TRUE(h.observer.events_of(EventKind::dropped, 1).empty()) << "holding is not dropping";
  h.sim_bus().with_hand(1, [](sim::SimHand& hand) { hand.drop_object(); });
  ASSERT_TRUE(h.run_until([&] { return !h.observer.events_of(EventKind::dropped, 1).empty(); }));
  const auto dropped = h.observer.events_of(EventKind::dropped, 1).front();
  EXPECT_NE(dropped.value, 3) << "the status that left 3 is reported";
  EXPECT_EQ(h.state(1)->grip, GripState::dropped);
  // The fingers close on to their target; the hand stays "dropped" until told otherwise.
  h.run_for(2s);
  EXPECT_EQ(h.state(1)->grip, GripState::dropped);
  EXPECT_EQ(h.observer.events_of(EventKind::dropped, 1).size(), 1u);
  EXPECT_TRUE(h.observer.events_of(EventKind::missed, 1).empty());
}

TEST(BusSchedulerEvents, OpeningAfterACatchIsNotADrop) {
  auto sim = sim_hands({1});
  sim[0].object_position = 50;
  SchedulerHarness h(sim, configs({1}));
  h.bring_up({1});
  ASSERT_EQ(h.call(1, grasp(40))->value().grasp, GraspOutcome::grasped);
  const auto released = h.call(1, cmd(CommandKind::release, 100));
  ASSERT_TRUE(released && released->ok()) << to_string(released->error());
  EXPECT_EQ(released->value().value, 100);
  EXPECT_TRUE(h.observer.events_of(EventKind::dropped, 1).empty());
  EXPECT_EQ(h.state(1)->grip, GripState::arrived);
}

TEST(BusSchedulerEvents, MoveArrivalIsReportedOncePerMotion) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.bring_up({1});
  ASSERT_TRUE(h.call(1, move(60))->ok());
  ASSERT_TRUE(h.run_until([&] { return h.observer.events_of(EventKind::arrived, 1).size() == 1; }));
  h.run_for(3s);  // many idle polls of status 2
  EXPECT_EQ(h.observer.events_of(EventKind::arrived, 1).size(), 1u);
  ASSERT_TRUE(h.call(1, move(20))->ok());
  ASSERT_TRUE(h.run_until([&] { return h.observer.events_of(EventKind::arrived, 1).size() == 2; }));
  EXPECT_EQ(h.observer.events_of(EventKind::arrived, 1).back().target, 20);
}

TEST(BusSchedulerEvents, AnArrivalSaysWhereItStoppedIsNotReadYetAndASampleWithTheStopFollows) {
  auto sim = sim_hands({1});
  sim[0].position_speed = 400.0;  // 8 % per 20 ms: no motion ends within one read
  SchedulerHarness h(sim, configs({1}));
  h.bring_up({1});
  for (std::int32_t target : {30, 90, 10}) {
    const std::size_t before = h.observer.events_of(EventKind::arrived, 1).size();
    ASSERT_TRUE(h.call(1, move(target))->ok());
    ASSERT_TRUE(
        h.run_until([&] { return h.observer.events_of(EventKind::arrived, 1).size() > before; }));
    const auto arrived = h.observer.events_of(EventKind::arrived, 1).back();
    EXPECT_EQ(arrived.position, std::nullopt) << "to " << target << ": not read yet";
    EXPECT_EQ(arrived.target, target);
    ASSERT_TRUE(
        h.run_until([&] { return sample_at(h.observer, 1, arrived.time, target).has_value(); }));
    const auto stopped = sample_at(h.observer, 1, arrived.time, target);
    EXPECT_EQ(stopped->grip, GripState::arrived);
    EXPECT_LE(stopped->updated_at - arrived.time, 2 * test_options().command_interval);
  }
}

TEST(BusSchedulerEvents, RotationArrivesOrIsBlocked) {
  auto sim = sim_hands({1});
  sim[0].rotation_obstacle = 40;
  SchedulerHarness h(sim, configs({1}));
  h.bring_up({1});
  ASSERT_TRUE(h.call(1, cmd(CommandKind::rotate_to, 30))->ok());
  ASSERT_TRUE(
      h.run_until([&] { return !h.observer.events_of(EventKind::rotation_arrived, 1).empty(); }));
  const auto arrived = h.observer.events_of(EventKind::rotation_arrived, 1).front();
  EXPECT_EQ(arrived.position, std::nullopt) << "not the rotation at home, where it started";
  EXPECT_EQ(arrived.target, 30);
  ASSERT_TRUE(
      h.run_until([&] { return sample_at(h.observer, 1, arrived.time, 30, true).has_value(); }));
  ASSERT_TRUE(h.call(1, cmd(CommandKind::rotate_to, 90))->ok());
  ASSERT_TRUE(
      h.run_until([&] { return !h.observer.events_of(EventKind::rotation_blocked, 1).empty(); }));
  const auto blocked = h.observer.events_of(EventKind::rotation_blocked, 1).front();
  EXPECT_EQ(blocked.position, std::nullopt) << "not 30, where it started";
  EXPECT_EQ(blocked.target, 90);
  ASSERT_TRUE(
      h.run_until([&] { return sample_at(h.observer, 1, blocked.time, 40, true).has_value(); }));
  EXPECT_EQ(h.state(1)->rotation, 40);
  EXPECT_EQ(h.state(1)->rotation_state, RotationState::blocked);
}

TEST(BusSchedulerEvents, UnsolicitedInitializationFrameIsConfirmedByARead) {
  auto options = test_options();
  options.poll_interval_moving = 10s;  // only the unsolicited frame can prompt a check soon
  auto sim = sim_hands({1});
  sim[0].init_time = 300ms;
  SchedulerHarness h(sim, configs({1}), options);
  h.run_until([&] { return h.state(1) && h.state(1)->online; });
  std::optional<CommandResult> result;
  h.scheduler->submit(1, cmd(CommandKind::initialize), [&](const CommandResult& r) { result = r; });
  const TimePoint start = h.clock.now();
  ASSERT_TRUE(h.run_until([&] { return result.has_value(); }, 5s));
  EXPECT_TRUE(result->ok());
  // Finished long before the 10 s check period: the frame was recognised.
  EXPECT_LT(h.clock.now() - start, 1s);
  EXPECT_EQ(h.scheduler->counters().unexpected_frames, 0u);
}

TEST(BusSchedulerEvents, ARebootedHandIsNoLongerInitialized) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.bring_up({1});
  h.sim_bus().with_hand(1, [&](sim::SimHand& hand) { hand.reboot(h.clock.now()); });
  ASSERT_TRUE(h.run_until([&] { return !h.state(1)->initialized; }));
  const auto faults = h.observer.events_of(EventKind::fault, 1);
  ASSERT_FALSE(faults.empty());
  EXPECT_NE(faults.back().message.find("not initialized"), std::string::npos);
  EXPECT_EQ(h.call(1, move(10))->error(), CommandError::not_initialized);
}

TEST(BusSchedulerEvents, EveryStateChangeIsPublishedWithARisingSequence) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.bring_up({1});
  ASSERT_TRUE(h.call(1, move(50))->ok());
  h.run_for(1s);
  std::uint64_t last = 0;
  for (const auto& s : h.observer.states) {
    EXPECT_GT(s.sequence, last);
    last = s.sequence;
  }
  ASSERT_TRUE(h.observer.last_state(1));
  EXPECT_EQ(h.observer.last_state(1)->position, 50);
  // Nothing changes at rest: no new samples.
  const std::size_t published = h.observer.states.size();
  h.run_for(3s);
  EXPECT_EQ(h.observer.states.size(), published);
}

TEST(BusSchedulerEvents, ACommandEndsAfterItsStateAndBeforeTheBatchEnd) {
  // The service holds a state back until the batch end and answers the
  // commands that ended with it first: the completion must see the new state
  // reported, and the batch end must follow it on the same pass.
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.bring_up({1});
  std::optional<CommandResult> result;
  std::size_t states_at_completion = 0;
  std::size_t ends_at_completion = 0;
  h.scheduler->submit(1, cmd(CommandKind::set_closing_force, 70), [&](const CommandResult& r) {
    result = r;
    states_at_completion = h.observer.states.size();
    ends_at_completion = h.observer.batch_ends.size();
  });
  ASSERT_TRUE(h.run_until([&] { return result.has_value(); }));
  ASSERT_TRUE(result->ok());
  ASSERT_TRUE(h.observer.last_state(1));
  EXPECT_EQ(h.observer.states.back().closing_force, 70);
  ASSERT_EQ(h.observer.batch_ends.size(), ends_at_completion + 1);
  EXPECT_EQ(h.observer.batch_ends.back().can_id, 1);
  EXPECT_EQ(h.observer.batch_ends.back().states, states_at_completion);
}

TEST(BusSchedulerEvents, EveryReportedStateIsFollowedByABatchEnd) {
  SchedulerHarness h(sim_hands({1, 2}), configs({1, 2}));
  h.bring_up({1, 2});
  ASSERT_TRUE(h.call(1, move(50))->ok());
  h.run_for(2s);
  // Each end closes exactly the reports since the previous one.
  std::size_t states = 0;
  std::size_t fresh = 0;
  for (const auto& end : h.observer.batch_ends) {
    EXPECT_EQ(end.states + end.fresh, states + fresh + 1);
    states = end.states;
    fresh = end.fresh;
  }
  EXPECT_EQ(states, h.observer.states.size());
  EXPECT_EQ(fresh, h.observer.fresh.size());
  EXPECT_FALSE(h.observer.fresh.empty());
}

/// Waits for the next read of `r` to go out and answers it with `value`
/// before the (slower) simulated hand does; the hand's own reply then arrives
/// as a stray frame.
void answer_next_read(SchedulerHarness& h, protocol::Register r, std::int32_t value) {
  const std::size_t before = h.sent_to(1, r).size();
  ASSERT_TRUE(h.run_until([&] { return h.sent_to(1, r).size() > before; }, 5s));
  protocol::Message reply = protocol::make_read(1, r);
  reply.data = value;
  h.recorder().inject(reply);
  h.run_for(1ms);
}

std::vector<HandEvent> faults_mentioning(const SchedulerHarness& h, const std::string& text) {
  std::vector<HandEvent> found;
  for (const auto& e : h.observer.events_of(EventKind::fault, 1)) {
    if (e.message.find(text) != std::string::npos) found.push_back(e);
  }
  return found;
}

TEST(BusSchedulerEvents, AStatusValueOutsideTheDocumentIsReportedOncePerAxis) {
  auto sim = sim_hands({1});
  sim[0].reply_delay = 5ms;
  SchedulerHarness h(sim, configs({1}));
  h.bring_up({1});
  answer_next_read(h, reg::kGripStatus, 7);
  ASSERT_EQ(faults_mentioning(h, "grip status 7").size(), 1u);
  // The same value on the other axis is news of its own.
  answer_next_read(h, reg::kRotationStatus, 7);
  const auto rotation = faults_mentioning(h, "rotation status 7");
  ASSERT_EQ(rotation.size(), 1u);
  EXPECT_EQ(rotation[0].value, 7);
  // Repeats on either axis are not reported again.
  answer_next_read(h, reg::kGripStatus, 7);
  answer_next_read(h, reg::kRotationStatus, 7);
  EXPECT_EQ(faults_mentioning(h, "grip status 7").size(), 1u);
  EXPECT_EQ(faults_mentioning(h, "rotation status 7").size(), 1u);
}

TEST(BusSchedulerEvents, An0x0802FrameIsTheFinishedSignalOnlyWithTheFeedbackEnabled) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  ASSERT_TRUE(h.run_until([&] { return h.state(1) && h.state(1)->online; }));
  // Initialization started by a raw write: the feedback (0x0801) was never enabled.
  std::optional<CommandResult> started;
  h.scheduler->submit(1, write(reg::kInitialize, 0), [&](const CommandResult& r) { started = r; });
  ASSERT_TRUE(h.run_until([&] { return started.has_value(); }));
  ASSERT_TRUE(started->ok());
  const auto unexpected_before = h.scheduler->counters().unexpected_frames;
  protocol::Message stray = protocol::make_read(1, reg::kInitialize);
  stray.data = 1;
  h.recorder().inject(stray);
  h.run_for(1ms);
  EXPECT_EQ(h.scheduler->counters().unexpected_frames - unexpected_before, 1u)
      << "without 0x0801 enabled an unsolicited 0x0802 frame is a stray frame";
  // The regular reads of 0x0802 still see the initialization finish.
  ASSERT_TRUE(h.run_until([&] { return h.state(1)->initialized; }, 5s));
  EXPECT_EQ(h.observer.events_of(EventKind::initialized, 1).size(), 1u);
}

}  // namespace
}  // namespace dh3::hand::test
