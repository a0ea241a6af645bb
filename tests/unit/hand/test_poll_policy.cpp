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

constexpr PollIntervals kIntervals{20ms, 50ms, 500ms};
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
      {"holding: the grip status, where a slip shows",
       {FingerActivity::holding, false, false},
       {500ms, 20ms, 500ms, 500ms, 500ms}},
      {"closing: the grip status (catch, arrival) and the moving position",
       {FingerActivity::closing, false, false},
       {50ms, 20ms, 500ms, 500ms, 500ms}},
      {"opening: the grip status (arrival) and the moving position",
       {FingerActivity::opening, false, false},
       {50ms, 20ms, 500ms, 500ms, 500ms}},
      {"rotating: the rotation status and the moving rotation",
       {FingerActivity::idle, true, false},
       {500ms, 500ms, 50ms, 20ms, 500ms}},
      {"holding while rotating: both statuses watched",
       {FingerActivity::holding, true, false},
       {500ms, 20ms, 50ms, 20ms, 500ms}},
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
  for (const auto& period : plan.period) EXPECT_EQ(period, Duration::zero());
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

TEST(PollPolicy, AHeldObjectsGripStatusWaitsAtMostOneFrameForTheSlowReads) {
  const PollPlan plan = plan_polls({FingerActivity::holding, false, false}, kIntervals);
  const auto reads = sequence(plan, 12, 20ms);
  // The slow reads (all due at once) go one at a time between grip-status reads.
  const std::vector<Index> expected = {position,        grip_status, rotation,    grip_status,
                                       rotation_status, grip_status, initialize,  grip_status,
                                       grip_status,     grip_status, grip_status, grip_status};
  EXPECT_EQ(reads, expected);
}

TEST(PollPolicy, ClosingFingersReadThePositionBetweenGripStatusReads) {
  const PollPlan plan = plan_polls({FingerActivity::closing, false, false}, kIntervals);
  const auto reads = sequence(plan, 30, 20ms, /*fresh=*/true);
  int grip = 0;
  int positions = 0;
  for (std::size_t i = 0; i < reads.size(); ++i) {
    if (reads[i] == grip_status) ++grip;
    if (reads[i] == position) ++positions;
    if (i > 0 && reads[i] != grip_status) {
      EXPECT_EQ(reads[i - 1], grip_status) << "two slow reads in a row at " << i;
    }
  }
  EXPECT_GE(grip, 18);      // about two frames in three
  EXPECT_GE(positions, 6);  // every 50 ms: every third frame at 20 ms pacing
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

TEST(PollPolicy, AfterASlowReadTheSlowOnesStillGoWhenNoWatchedOneIsDue) {
  // Watch period much longer than the pacing: the slow reads need not wait.
  const PollPlan plan = plan_polls({FingerActivity::holding, false, false}, {200ms, 50ms, 500ms});
  const TimePoint start = TimePoint{} + 1h;
  PollTimes last{};
  last[grip_status] = start;
  last[position] = start;
  EXPECT_EQ(next_poll(plan, last, position, start + 20ms), std::optional<std::size_t>(rotation));
}

}  // namespace
}  // namespace dh3::hand
