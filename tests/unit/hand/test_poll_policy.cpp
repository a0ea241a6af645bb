// The polling policy: which status registers a hand reads how often, by what
// it is doing, and which one goes next.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "dh3/hand/poll_policy.hpp"

namespace dh3::hand {
namespace {

using namespace std::chrono_literals;
namespace reg = protocol::reg;

// No position read during a motion: the plan that gives events their floor.
constexpr PollIntervals kIntervals{20ms, 50ms, 500ms, 0ms};
constexpr std::optional<Duration> kNever = std::nullopt;

enum Index : std::size_t { position, grip_status, rotation, rotation_status, initialize };

struct PlanCase {
  std::string name;
  PollActivity activity;
  // Periods of position, grip status, rotation, rotation status, initialization flag.
  std::array<std::optional<Duration>, kPolledCount> expected;
};

TEST(PollPolicy, RegistersAreTheStatusOnesInTheOrderOfTheOldRound) {
  EXPECT_EQ(kPolledRegisters[position], reg::kPosition);
  EXPECT_EQ(kPolledRegisters[grip_status], reg::kGripStatus);
  EXPECT_EQ(kPolledRegisters[rotation], reg::kRotation);
  EXPECT_EQ(kPolledRegisters[rotation_status], reg::kRotationStatus);
  EXPECT_EQ(kPolledRegisters[initialize], reg::kInitialize);
}

TEST(PollPolicy, EachStateReadsWhatCanChangeOftenAndTheRestAtRest) {
  const std::vector<PlanCase> cases = {
      {"idle: everything at the idle period, like the old round",
       {FingerActivity::idle, false, false},
       {500ms, 500ms, 500ms, 500ms, 500ms}},
      {"holding: only the grip status, where a slip shows",
       {FingerActivity::holding, false, false},
       {kNever, 20ms, kNever, kNever, kNever}},
      {"closing: only the grip status (catch, arrival)",
       {FingerActivity::closing, false, false},
       {kNever, 20ms, kNever, kNever, kNever}},
      {"opening: only the grip status (arrival)",
       {FingerActivity::opening, false, false},
       {kNever, 20ms, kNever, kNever, kNever}},
      {"rotating: only the rotation status",
       {FingerActivity::idle, true, false},
       {kNever, kNever, kNever, 20ms, kNever}},
      {"holding while rotating: both statuses, nothing else",
       {FingerActivity::holding, true, false},
       {kNever, 20ms, kNever, 20ms, kNever}},
      {"initializing: as while moving; the flag has its own check",
       {FingerActivity::idle, false, true},
       {50ms, 50ms, 50ms, 50ms, kNever}},
  };
  for (const auto& c : cases) {
    const PollPlan plan = plan_polls(c.activity, kIntervals);
    for (std::size_t i = 0; i < kPolledCount; ++i) {
      EXPECT_EQ(plan.period[i], c.expected[i])
          << c.name << ": register " << protocol::name(kPolledRegisters[i]);
    }
  }
}

TEST(PollPolicy, AnIntervalShorterThanTheWatchOneIsNeverMadeLonger) {
  // Polls always due (tests and benchmarks set the idle period to 0).
  const PollPlan plan = plan_polls({FingerActivity::holding, true, false}, {20ms, 50ms, 0ms});
  EXPECT_EQ(plan.period[grip_status], Duration::zero());
  EXPECT_EQ(plan.period[rotation_status], Duration::zero());
}

/// The registers read, one per `step`, from `start` on, with every register
/// last read at `start` unless `fresh` is false (then all are due at once).
std::vector<Index> sequence(const PollPlan& plan, int count, Duration step, bool fresh = false) {
  const TimePoint start = TimePoint{} + 1h;
  PollTimes last{};
  if (fresh) last.fill(start);
  std::optional<std::size_t> previous;
  std::vector<Index> out;
  for (TimePoint now = start; static_cast<int>(out.size()) < count; now += step) {
    if (auto next = next_poll(plan, last, previous, now)) {
      out.push_back(static_cast<Index>(*next));
      last[*next] = now;
      previous = next;
    }
  }
  return out;
}

TEST(PollPolicy, ByDefaultAMotionsPositionIsReadFiveTimesASecondBesideItsStatus) {
  const PollIntervals defaults{};
  EXPECT_EQ(defaults.during_motion, 200ms);
  const PollPlan closing = plan_polls({FingerActivity::closing, false, false}, defaults);
  EXPECT_EQ(closing.period[position], 200ms);
  EXPECT_EQ(closing.period[grip_status], 20ms);
  const PollPlan opening = plan_polls({FingerActivity::opening, false, false}, defaults);
  EXPECT_EQ(opening.period[position], 200ms);
  const PollPlan rotating = plan_polls({FingerActivity::idle, true, false}, defaults);
  EXPECT_EQ(rotating.period[rotation], 200ms);
  EXPECT_EQ(rotating.period[position], kNever) << "the fingers do not move";
  const PollPlan holding = plan_polls({FingerActivity::holding, false, false}, defaults);
  EXPECT_EQ(holding.period[position], kNever) << "fingers at rest on an object do not move";

  // One second of closing with a frame every 20 ms: five positions, and the
  // grip status never waits more than the one frame a position read takes.
  const auto reads = sequence(closing, 50, 20ms, true);
  int positions = 0;
  for (std::size_t i = 0; i < reads.size(); ++i) {
    if (reads[i] != position) continue;
    ++positions;
    if (i > 0) {
      EXPECT_EQ(reads[i - 1], grip_status) << "two reads in a row took the status's frames";
    }
  }
  EXPECT_EQ(positions, 5);
}

TEST(PollPolicy, AHandAtRestReadsItsRoundInOrderThenWaitsTheIdlePeriod) {
  const PollPlan plan = plan_polls({}, kIntervals);
  // Every 20 ms a chance to send: five reads in a row, then nothing for 500 ms.
  const TimePoint start = TimePoint{} + 1h;
  PollTimes last{};
  std::optional<std::size_t> previous;
  std::vector<std::pair<Index, Duration>> reads;
  for (TimePoint now = start; now < start + 1s; now += 20ms) {
    if (auto next = next_poll(plan, last, previous, now)) {
      reads.emplace_back(static_cast<Index>(*next), now - start);
      last[*next] = now;
      previous = next;
    }
  }
  const std::vector<std::pair<Index, Duration>> expected = {
      {position, 0ms},          {grip_status, 20ms}, {rotation, 40ms},     {rotation_status, 60ms},
      {initialize, 80ms},       {position, 500ms},   {grip_status, 520ms}, {rotation, 540ms},
      {rotation_status, 560ms}, {initialize, 580ms}};
  EXPECT_EQ(reads, expected);
}

/// When each read of `sequence` went out, one chance to send every `step`.
std::vector<Duration> read_times(const PollPlan& plan, Duration span, Duration step) {
  const TimePoint start = TimePoint{} + 1h;
  PollTimes last{};
  last.fill(start - 10s);  // the idle round was read long ago: all due
  std::optional<std::size_t> previous;
  std::vector<Duration> out;
  for (TimePoint now = start; now < start + span; now += step) {
    if (auto next = next_poll(plan, last, previous, now)) {
      out.push_back(now - start);
      last[*next] = now;
      previous = next;
    }
  }
  return out;
}

TEST(PollPolicy, AWatchedGripStatusTakesEveryFrameSoAChangeIsHeardWithinOneInterval) {
  // Holding, closing and opening: every chance to send, at 20 ms pacing and at
  // 22 ms (a transfer box's margin), reads the grip status and nothing else,
  // so the worst case from a change to its read is one frame interval.
  for (const auto fingers :
       {FingerActivity::holding, FingerActivity::closing, FingerActivity::opening}) {
    const PollPlan plan = plan_polls({fingers, false, false}, kIntervals);
    for (const Duration step : {Duration(20ms), Duration(22ms)}) {
      const auto reads = sequence(plan, 40, step);
      EXPECT_EQ(reads, std::vector<Index>(40, grip_status));
      const auto times = read_times(plan, 1s, step);
      for (std::size_t i = 1; i < times.size(); ++i) {
        EXPECT_EQ(times[i] - times[i - 1], step) << "a chance to send went unused";
      }
    }
  }
}

TEST(PollPolicy, HoldingWhileRotatingSharesTheFramesBetweenTheTwoStatuses) {
  // Two watched statuses: each waits at most one frame for the other.
  const PollPlan plan = plan_polls({FingerActivity::holding, true, false}, kIntervals);
  const auto reads = sequence(plan, 20, 20ms);
  for (std::size_t i = 0; i < reads.size(); ++i) {
    EXPECT_TRUE(reads[i] == grip_status || reads[i] == rotation_status) << i;
    if (i > 0) {
      EXPECT_NE(reads[i], reads[i - 1]) << "the same status twice in a row at " << i;
    }
  }
}

TEST(PollPolicy, NothingIsDueBeforeItsPeriodAndTheNextDueTimeSaysWhen) {
  const PollPlan plan = plan_polls({FingerActivity::holding, false, false}, kIntervals);
  const TimePoint start = TimePoint{} + 1h;
  PollTimes last{};
  last.fill(start);
  EXPECT_EQ(next_poll(plan, last, grip_status, start + 19ms), std::nullopt);
  EXPECT_EQ(next_poll_due(plan, last), start + 20ms);
  EXPECT_EQ(next_poll(plan, last, grip_status, start + 20ms),
            std::optional<std::size_t>(grip_status));
}

TEST(PollPolicy, AfterASlowReadTheSlowOnesStillGoWhenNoFastOneIsDue) {
  // A plan with one register faster than the rest, its period much longer
  // than the pacing: the slow reads need not wait for it.
  PollPlan plan;
  plan.period = {500ms, 200ms, 500ms, 500ms, 500ms};
  const TimePoint start = TimePoint{} + 1h;
  PollTimes last{};
  last[grip_status] = start;
  last[position] = start;
  EXPECT_EQ(next_poll(plan, last, position, start + 20ms), std::optional<std::size_t>(rotation));
}

}  // namespace
}  // namespace dh3::hand
