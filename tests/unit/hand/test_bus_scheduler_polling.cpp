// Polling by what can change (poll_policy.hpp), as the hand sees it: which
// status reads go out in each state of a hand, how soon a slip, catch or
// arrival is seen (within one command interval: the floor, since only a read
// of the status tells), that the pacing and the line budget still hold, and
// that the state says when the hand last answered.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <map>
#include <set>
#include <string>

#include "unit/hand/scheduler_harness.hpp"

namespace dh3::hand::test {
namespace {

/// Reads of `r` sent to hand `id` from `from` on.
std::vector<TimePoint> reads_of(const SchedulerHarness& h, std::uint8_t id, protocol::Register r,
                                TimePoint from) {
  std::vector<TimePoint> out;
  for (const auto& s : h.sent_to(id, r)) {
    if (s.at >= from && s.message.access == protocol::Access::read) out.push_back(s.at);
  }
  return out;
}

Duration longest_gap(const std::vector<TimePoint>& times) {
  Duration longest{};
  for (std::size_t i = 1; i < times.size(); ++i)
    longest = std::max(longest, times[i] - times[i - 1]);
  return longest;
}

/// Hand 1 with an object at 40, initialized and holding it.
void grasp_object(SchedulerHarness& h) {
  h.sim_bus().with_hand(1, [](sim::SimHand& hand) { hand.place_object(40); });
  const auto result = h.call(1, grasp(50));
  ASSERT_TRUE(result && result->ok());
  ASSERT_EQ(result->value().grasp, GraspOutcome::grasped);
}

TEST(BusSchedulerPolling, AHandAtRestThatHoldsNothingReadsItsFiveRegistersOncePerIdlePeriod) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.bring_up({1});
  h.run_for(1s);  // the reads after initialization settle
  const TimePoint from = h.clock.now();
  h.run_for(5s);
  // As before polling followed the state: one round of five reads per 500 ms.
  for (const auto r :
       {reg::kPosition, reg::kGripStatus, reg::kRotation, reg::kRotationStatus, reg::kInitialize}) {
    const auto reads = reads_of(h, 1, r, from);
    EXPECT_GE(reads.size(), 9u) << protocol::name(r);
    EXPECT_LE(reads.size(), 11u) << protocol::name(r);
  }
  std::size_t frames = 0;
  for (const auto& s : h.sent_to(1)) frames += s.at >= from ? 1 : 0;
  EXPECT_LE(frames, 55u);
}

TEST(BusSchedulerPolling, AHeldObjectsGripStatusIsReadEveryCommandIntervalAndNothingElse) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.bring_up({1});
  grasp_object(h);
  h.run_for(100ms);  // the read of where the fingers stopped
  const TimePoint from = h.clock.now();
  h.run_for(2s);
  const auto grip = reads_of(h, 1, reg::kGripStatus, from);
  EXPECT_GE(grip.size(), 99u);  // every one of the 100 chances in 2 s at 20 ms
  EXPECT_EQ(longest_gap(grip), test_options().command_interval);
  for (const auto r : {reg::kPosition, reg::kRotation, reg::kRotationStatus, reg::kInitialize}) {
    EXPECT_TRUE(reads_of(h, 1, r, from).empty()) << protocol::name(r) << " took a slip's slot";
  }
}

TEST(BusSchedulerPolling, AHandThatRebootsWhileHoldingIsSeenToDropThenNotInitialized) {
  // Its initialization flag is not read while it holds: the reboot shows as a
  // drop (status 0), and the idle round that follows finds the flag cleared.
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.bring_up({1});
  grasp_object(h);
  h.run_for(100ms);
  h.sim_bus().with_hand(1, [&](sim::SimHand& hand) { hand.reboot(h.clock.now()); });
  ASSERT_TRUE(h.run_until([&] { return !h.observer.events_of(EventKind::dropped, 1).empty(); }));
  ASSERT_TRUE(h.run_until([&] { return !h.state(1)->initialized; }, 2s));
}

TEST(BusSchedulerPolling, ASlipIsSeenWithinOneCommandInterval) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.bring_up({1});
  for (int attempt = 0; attempt < 6; ++attempt) {
    ASSERT_TRUE(h.call(1, cmd(CommandKind::release, 100))->ok());
    grasp_object(h);
    h.run_for(std::chrono::milliseconds(300 + 7 * attempt));  // drops at varied phases
    const std::size_t before = h.observer.events_of(EventKind::dropped, 1).size();
    const TimePoint dropped_at = h.clock.now();
    h.sim_bus().with_hand(1, [](sim::SimHand& hand) { hand.drop_object(); });
    ASSERT_TRUE(h.run_until(
        [&] { return h.observer.events_of(EventKind::dropped, 1).size() > before; }, 2s));
    const Duration seen_after =
        h.observer.events_of(EventKind::dropped, 1).back().time - dropped_at;
    EXPECT_LE(seen_after, test_options().command_interval) << "attempt " << attempt;
  }
}

/// The floor: no position (rotation) read while a motion runs.
SchedulerOptions no_position_during_motion() {
  SchedulerOptions options = test_options();
  options.poll_interval_position_moving = Duration::zero();
  return options;
}

TEST(BusSchedulerPolling, ByDefaultAMovingHandsPositionIsPublishedFiveTimesASecond) {
  auto sim = sim_hands({1});
  sim[0].position_speed = 10.0;  // 100 % takes 10 s
  SchedulerHarness h(sim, configs({1}));
  h.bring_up({1});
  h.scheduler->submit(1, grasp(50), [](const CommandResult&) {});
  h.run_for(100ms);
  const TimePoint from = h.clock.now();
  h.run_for(1s);
  const auto positions = reads_of(h, 1, reg::kPosition, from);
  EXPECT_GE(positions.size(), 4u);
  EXPECT_LE(positions.size(), 6u);
  // Each read shows as a status sample with the fingers further closed.
  std::set<std::int32_t> published;
  for (const HandState& state : h.observer.states) {
    if (state.can_id == 1 && state.updated_at >= from && state.grip == GripState::moving) {
      published.insert(state.position);
    }
  }
  EXPECT_GE(published.size(), 4u);
  // The grip status still gets every other frame at least.
  const auto grip = reads_of(h, 1, reg::kGripStatus, from);
  EXPECT_LE(longest_gap(grip), 2 * test_options().command_interval);
}

TEST(BusSchedulerPolling, ClosingFingersReadTheGripStatusInEveryFrameAndNothingElse) {
  auto sim = sim_hands({1});
  sim[0].position_speed = 10.0;  // 100 % takes 10 s
  SchedulerHarness h(sim, configs({1}), no_position_during_motion());
  h.bring_up({1});
  h.scheduler->submit(1, grasp(50), [](const CommandResult&) {});
  h.run_for(200ms);
  const TimePoint from = h.clock.now();
  h.run_for(1s);
  const auto grip = reads_of(h, 1, reg::kGripStatus, from);
  EXPECT_GE(grip.size(), 49u);
  EXPECT_EQ(longest_gap(grip), test_options().command_interval);
  // Where the fingers are is read once they stopped (the state says so).
  EXPECT_TRUE(reads_of(h, 1, reg::kPosition, from).empty());
  EXPECT_TRUE(reads_of(h, 1, reg::kRotationStatus, from).empty());
}

TEST(BusSchedulerPolling, ARotationReadsTheRotationStatusInEveryFrameAndNothingElse) {
  auto sim = sim_hands({1});
  sim[0].rotation_speed = 10.0;
  SchedulerHarness h(sim, configs({1}), no_position_during_motion());
  h.bring_up({1});
  h.run_for(1s);
  ASSERT_TRUE(h.call(1, cmd(CommandKind::rotate_to, 100))->ok());
  const TimePoint from = h.clock.now();
  h.run_for(1s);
  const auto status = reads_of(h, 1, reg::kRotationStatus, from);
  EXPECT_GE(status.size(), 49u);
  EXPECT_EQ(longest_gap(status), test_options().command_interval);
  EXPECT_TRUE(reads_of(h, 1, reg::kRotation, from).empty());
  EXPECT_TRUE(reads_of(h, 1, reg::kGripStatus, from).empty());
}

TEST(BusSchedulerPolling, AnArrivalIsReportedWithinOneCommandInterval) {
  // The grip status read in every frame shows it within one interval, and the
  // event goes out on that read; where the fingers stopped is read after it.
  auto sim = sim_hands({1});
  sim[0].position_speed = 100.0;
  SchedulerHarness h(sim, configs({1}), no_position_during_motion());
  h.bring_up({1});
  for (const std::int32_t target : {30, 70, 45, 90}) {
    ASSERT_TRUE(h.call(1, move(target))->ok());
    TimePoint arrived_at{};
    ASSERT_TRUE(h.run_until([&] {
      h.sim_bus().with_hand(1, [&](sim::SimHand& hand) {
        if (hand.grip_status() == protocol::GripStatus::arrived && arrived_at == TimePoint{}) {
          arrived_at = hand.grip_status_since();
        }
      });
      return arrived_at != TimePoint{};
    }));
    const std::size_t before = h.observer.events_of(EventKind::arrived, 1).size();
    ASSERT_TRUE(h.run_until(
        [&] { return h.observer.events_of(EventKind::arrived, 1).size() > before; }, 2s));
    const Duration seen_after =
        h.observer.events_of(EventKind::arrived, 1).back().time - arrived_at;
    EXPECT_LE(seen_after, test_options().command_interval) << "to " << target;
  }
}

TEST(BusSchedulerPolling, AShortMotionsArrivalIsCheckedWithOneReadOfThePosition) {
  // Fingers that reach the target within a millisecond: the first grip status
  // after the command says 2 with no 0 before it, and the position last read
  // is far from the target, so it might be from before the command. One read
  // of the position tells; the event goes out on it, with that position.
  auto sim = sim_hands({1});
  sim[0].position_speed = 10000.0;
  SchedulerHarness h(sim, configs({1}), no_position_during_motion());
  h.bring_up({1});
  for (const std::int32_t target : {30, 70}) {
    const std::size_t before = h.observer.events_of(EventKind::arrived, 1).size();
    ASSERT_TRUE(h.call(1, move(target))->ok());
    ASSERT_TRUE(h.run_until(
        [&] { return h.observer.events_of(EventKind::arrived, 1).size() > before; }, 2s));
    const auto arrived = h.observer.events_of(EventKind::arrived, 1).back();
    EXPECT_EQ(arrived.position, target);
    // The last read before the event was the grip status that showed the arrival.
    const RecordingBus::Sent* last = nullptr;
    for (const auto& sent : h.recorder().sent) {
      if (sent.message.hand_id == 1 && sent.at <= arrived.time) last = &sent;
    }
    ASSERT_NE(last, nullptr);
    EXPECT_EQ(last->message.reg, reg::kPosition)
        << "to " << target << ": the event waited for " << protocol::describe(last->message);
    EXPECT_LE(arrived.time - last->at, test_options().command_interval);
  }
}

/// Every pair of consecutive frames to one hand closer than `interval`.
std::vector<std::string> too_close(const RecordingBus& bus, Duration interval) {
  std::map<std::uint8_t, TimePoint> last;
  std::vector<std::string> out;
  for (const auto& sent : bus.sent) {
    const auto it = last.find(sent.message.hand_id);
    if (it != last.end() && sent.at - it->second < interval) {
      out.push_back(
          fmt::format("hand {}: {}", sent.message.hand_id, protocol::describe(sent.message)));
    }
    last[sent.message.hand_id] = sent.at;
  }
  return out;
}

/// 32 hands on a 500 kbps line (135-bit frames, a controller queue of 4),
/// each with an object at 40: more grip-status reads than 80 % of the line
/// carries, for the line budget to share.
struct HoldingLine {
  static std::vector<std::uint8_t> hand_ids() {
    std::vector<std::uint8_t> ids;
    for (int id = 1; id <= 32; ++id) ids.push_back(static_cast<std::uint8_t>(id));
    return ids;
  }
  static std::vector<sim::SimHandOptions> holding(const std::vector<std::uint8_t>& ids) {
    auto sim = sim_hands(ids);
    for (auto& hand : sim) hand.object_position = 40;
    return sim;
  }
  static sim::SimBusOptions full_line() {
    sim::SimBusOptions line;
    line.bit_rate = 500'000;
    line.bits_per_frame = 135;
    line.tx_queue_length = 4;
    return line;
  }

  std::vector<std::uint8_t> ids = hand_ids();
  SchedulerHarness h{holding(ids), configs(ids), test_options(), full_line()};

  /// Brings every hand up and grasps with each; false unless every grasp
  /// ended within 10 s.
  [[nodiscard]] bool grasp_all(std::map<std::uint8_t, std::optional<CommandResult>>& results) {
    h.bring_up(ids);
    for (auto id : ids) {
      h.scheduler->submit(id, grasp(50),
                          [&results, id](const CommandResult& r) { results[id] = r; });
    }
    return h.run_until([&] { return results.size() == ids.size(); }, 10s);
  }
};

TEST(BusSchedulerPolling, ManyHoldingHandsKeepThePacingAndTheLineBudget) {
  // 32 hands on a 500 kbps line, all holding: they would like a grip-status
  // read each every 20 ms, more than 80 % of the line carries; the budget
  // shares what it carries and every hand's slips are still watched.
  HoldingLine line;
  SchedulerHarness& h = line.h;
  const std::vector<std::uint8_t>& ids = line.ids;
  std::map<std::uint8_t, std::optional<CommandResult>> results;
  ASSERT_TRUE(line.grasp_all(results));
  for (auto& [id, result] : results) ASSERT_TRUE(result->ok()) << "hand " << int(id);
  const TimePoint from = h.clock.now();
  const std::size_t sent_before = h.recorder().sent.size();
  h.run_for(3s);

  EXPECT_TRUE(too_close(h.recorder(), test_options().command_interval).empty());
  // Requests and replies of 135 bits within 80 % of 500 kbps.
  const double requests = static_cast<double>(h.recorder().sent.size() - sent_before);
  const double load = requests * 2 * 135 / (500'000.0 * 3);
  EXPECT_LE(load, 0.81);
  for (auto id : ids) {
    const auto grip = reads_of(h, id, reg::kGripStatus, from);
    EXPECT_GE(grip.size(), 60u) << "hand " << int(id);  // ~30 ms apart on a full line
    EXPECT_LE(longest_gap(grip), 100ms) << "hand " << int(id);
  }
  EXPECT_EQ(h.scheduler->counters().timeouts, 0u);
}

TEST(BusSchedulerPolling, HoldingHandsKeepTheirSpacingWhileAnotherHandCycles) {
  // 32 hands holding on a full 500 kbps line; one at a time drops, is released
  // and grasps again (commands, confirming reads, an idle round in between).
  // The others' grip status is still read once per round of the line budget
  // (32 requests at 0.675 ms: 21.6 ms), never a round later: a slip is heard
  // within one spacing of it.
  HoldingLine line;
  SchedulerHarness& h = line.h;
  const std::vector<std::uint8_t>& ids = line.ids;
  std::map<std::uint8_t, std::optional<CommandResult>> results;
  ASSERT_TRUE(line.grasp_all(results));
  const TimePoint from = h.clock.now();
  std::set<std::uint8_t> cycled;
  for (int c = 0; c < 10; ++c) {
    const auto id = static_cast<std::uint8_t>(1 + (c * 7) % ids.size());
    cycled.insert(id);
    h.run_for(std::chrono::milliseconds(200 + 13 * c));  // at varied phases
    h.sim_bus().with_hand(id, [](sim::SimHand& hand) { hand.drop_object(); });
    h.run_for(50ms);
    ASSERT_TRUE(h.call(id, cmd(CommandKind::release, 100))->ok());
    h.sim_bus().with_hand(id, [](sim::SimHand& hand) { hand.place_object(40); });
    ASSERT_EQ(h.call(id, grasp(50))->value().grasp, GraspOutcome::grasped);
  }
  for (auto id : ids) {
    if (cycled.count(id) > 0) continue;
    EXPECT_LE(longest_gap(reads_of(h, id, reg::kGripStatus, from)), 22ms) << "hand " << int(id);
  }
  EXPECT_TRUE(too_close(h.recorder(), test_options().command_interval).empty());
}

TEST(BusSchedulerPolling, TheStateSaysWhenTheHandLastAnsweredAndStaysFreshAtRest) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.bring_up({1});
  h.run_for(1s);
  const TimePoint first = h.state(1)->read_at;
  EXPECT_NE(first, TimePoint{});
  EXPECT_LE(first, h.clock.now());
  const std::size_t samples = h.observer.states.size();
  const std::size_t fresh = h.observer.fresh.size();
  h.run_for(3s);
  // Nothing changed, so no new sample; but the published state was read again.
  EXPECT_EQ(h.observer.states.size(), samples);
  ASSERT_GE(h.observer.fresh.size(), fresh + 4);  // once per 500 ms idle round
  TimePoint last = first;
  for (std::size_t i = fresh; i < h.observer.fresh.size(); ++i) {
    EXPECT_GT(h.observer.fresh[i].read_at, last);
    EXPECT_EQ(h.observer.fresh[i].position, h.observer.last_state(1)->position);
    last = h.observer.fresh[i].read_at;
  }
  EXPECT_GE(h.state(1)->read_at, last);
  EXPECT_GE(h.clock.now() - h.state(1)->read_at, Duration::zero());
  EXPECT_LE(h.clock.now() - h.state(1)->read_at, 500ms);
}

TEST(BusSchedulerPolling, ASampleCarriesTheTimeOfTheReplyThatChangedIt) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.bring_up({1});
  ASSERT_TRUE(h.call(1, move(30))->ok());
  h.run_for(1s);
  const auto state = h.observer.last_state(1);
  ASSERT_TRUE(state);
  EXPECT_EQ(state->position, 30);
  // Published as the reply came in: read at the moment of publication.
  EXPECT_EQ(state->read_at, state->updated_at);
}

TEST(BusSchedulerPolling, AWarmedHandIsPublishedAsSeenUntilItsOwnRepliesSayOtherwise) {
  // Hand 1 answers as a hand the simulator never initialized.
  SchedulerHarness h(sim_hands({1}), configs({1}));
  HandState seen;
  seen.can_id = 1;
  seen.initialized = true;
  seen.position = 30;
  seen.closing_force = 80;
  h.scheduler->warm({seen});
  // Published at once, before a frame went out: what the standby saw.
  ASSERT_TRUE(h.recorder().sent.empty());
  const auto warm = h.observer.last_state(1);
  ASSERT_TRUE(warm);
  EXPECT_TRUE(warm->initialized);
  EXPECT_EQ(warm->position, 30);
  EXPECT_EQ(warm->closing_force, 80);
  // The hand's answers replace it; nothing initializes the hand.
  ASSERT_TRUE(h.run_until([&] {
    const auto s = h.state(1);
    return s && s->online && !s->initialized && s->position != 30;
  })) << "the hand's own readings never replaced the warm state";
  for (const auto& sent : h.sent_to(1, reg::kInitialize)) {
    EXPECT_EQ(sent.message.access, protocol::Access::read) << "the warmed hand was initialized";
  }
}

}  // namespace
}  // namespace dh3::hand::test
