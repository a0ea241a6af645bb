// How the scheduler shares one bus: pacing per hand, commands before polls,
// round robin across 1, 8 and 64 hands, one frame in flight per hand, a silent
// hand that delays nobody, and a full controller queue.

#include <gtest/gtest.h>

#include <algorithm>
#include <map>

#include "unit/hand/scheduler_harness.hpp"

namespace dh3::hand::test {
namespace {

std::vector<std::uint8_t> ids_1_to(int n) {
  std::vector<std::uint8_t> ids;
  for (int i = 1; i <= n; ++i) ids.push_back(static_cast<std::uint8_t>(i));
  return ids;
}

TEST(BusSchedulerScheduling, FramesToOneHandAreAtLeastTheCommandIntervalApart) {
  SchedulerHarness h(sim_hands({1, 2}), configs({1, 2}));
  h.bring_up({1, 2});
  for (int i = 0; i < 5; ++i) h.scheduler->submit(1, move(10 * i), [](const CommandResult&) {});
  h.run_for(2s);
  for (std::uint8_t id : {1, 2}) {
    const auto sent = h.sent_to(id);
    ASSERT_GT(sent.size(), 10u);
    for (std::size_t i = 1; i < sent.size(); ++i) {
      EXPECT_GE(sent[i].at - sent[i - 1].at, 20ms)
          << "hand " << int(id) << ": " << protocol::describe(sent[i].message);
    }
  }
}

TEST(BusSchedulerScheduling, CommandIntervalIsConfigurableDownToZero) {
  auto options = test_options();
  options.command_interval = 0ms;
  options.poll_interval_idle = 0ms;
  options.poll_interval_moving = 0ms;
  SchedulerHarness h(sim_hands({1}), configs({1}), options);
  h.run_for(100ms);
  // With no pacing a hand that answers at once is read every step (1 ms).
  EXPECT_GE(h.sent_to(1).size(), 90u);
}

TEST(BusSchedulerScheduling, CommandsGoBeforeStatusPolls) {
  auto options = test_options();
  options.poll_interval_idle = 0ms;  // polls always due
  options.poll_interval_moving = 0ms;
  SchedulerHarness h(sim_hands({1}), configs({1}), options);
  h.bring_up({1});
  const std::size_t before = h.recorder().sent.size();
  for (int i = 0; i < 3; ++i) {
    h.scheduler->submit(1, cmd(CommandKind::set_closing_force, 30 + i),
                        [](const CommandResult&) {});
  }
  h.run_for(200ms);
  // Once a poll in flight is answered, the three force writes go next, back to back.
  std::vector<protocol::Register> order;
  for (std::size_t i = before; i < h.recorder().sent.size(); ++i) {
    order.push_back(h.recorder().sent[i].message.reg);
  }
  const auto first_write = std::find(order.begin(), order.end(), reg::kClosingForce);
  ASSERT_NE(first_write, order.end());
  EXPECT_LE(first_write - order.begin(), 1) << "a command waited behind polls";
  ASSERT_GE(order.end() - first_write, 3);
  EXPECT_EQ(*(first_write + 1), reg::kClosingForce);
  EXPECT_EQ(*(first_write + 2), reg::kClosingForce);
}

TEST(BusSchedulerScheduling, AtMostOneFrameInFlightPerHand) {
  auto sim = sim_hands({1});
  sim[0].reply_delay = 15ms;
  auto options = test_options();
  options.command_interval = 0ms;
  SchedulerHarness h(sim, configs({1}), options);
  h.bring_up({1});
  // (During initialization the unsolicited 0x0802 frame is indistinguishable
  // from the answer to an 0x0802 read, so only what follows is measured.)
  const std::size_t before = h.sent_to(1).size();
  for (int i = 0; i < 10; ++i) {
    h.scheduler->submit(1, read(reg::kPosition), [](const CommandResult&) {});
  }
  h.run_for(1s);
  auto sent = h.sent_to(1);
  sent.erase(sent.begin(), sent.begin() + static_cast<std::ptrdiff_t>(before));
  ASSERT_GT(sent.size(), 10u);
  // With a 15 ms reply delay and no pacing, a new frame only after the reply.
  for (std::size_t i = 1; i < sent.size(); ++i) {
    EXPECT_GE(sent[i].at - sent[i - 1].at, 15ms)
        << protocol::describe(sent[i - 1].message) << " then "
        << protocol::describe(sent[i].message) << " at "
        << (sent[i].at - sent[0].at).count() / 1000000;
  }
}

TEST(BusSchedulerScheduling, StatusIsPolledFasterWhileMovingThanAtRest) {
  auto sim = sim_hands({1});
  sim[0].position_speed = 10.0;  // 100 % takes 10 s
  SchedulerHarness h(sim, configs({1}));
  h.bring_up({1});
  auto grip_polls_during = [&](Duration span) {
    const std::size_t before = h.sent_to(1, reg::kGripStatus).size();
    h.run_for(span);
    return h.sent_to(1, reg::kGripStatus).size() - before;
  };
  const std::size_t at_rest = grip_polls_during(4s);
  ASSERT_TRUE(h.call(1, move(0))->ok());
  const std::size_t moving = grip_polls_during(4s);
  // 500 ms at rest vs 50 ms (bounded by 4 reads x 20 ms pacing) while moving.
  EXPECT_LE(at_rest, 9u);
  EXPECT_GE(moving, 4 * at_rest);
}

class BusSchedulerFairness : public ::testing::TestWithParam<int> {};

void expect_fair_share(const SchedulerHarness& h, int n) {
  std::map<std::uint8_t, std::size_t> per_hand;
  for (const auto& s : h.recorder().sent) ++per_hand[s.message.hand_id];
  ASSERT_EQ(per_hand.size(), static_cast<std::size_t>(n));
  std::size_t lo = SIZE_MAX;
  std::size_t hi = 0;
  for (const auto& [id, count] : per_hand) {
    lo = std::min(lo, count);
    hi = std::max(hi, count);
  }
  ASSERT_GT(lo, 0u);
  EXPECT_GE(static_cast<double>(lo), 0.8 * static_cast<double>(hi))
      << "slowest hand " << lo << " frames, fastest " << hi;
}

// No pacing and no line time: every hand is served as fast as it answers, and
// round robin gives each the same share of the scheduler's sends.
TEST_P(BusSchedulerFairness, EveryHandGetsItsShareWithoutPacing) {
  const int n = GetParam();
  auto options = test_options();
  options.command_interval = 0ms;
  options.poll_interval_idle = 0ms;
  options.poll_interval_moving = 0ms;
  auto sim = sim_hands(ids_1_to(n));
  for (auto& hand : sim) hand.reply_delay = 2ms;
  SchedulerHarness h(sim, configs(ids_1_to(n)), options);
  h.run_for(2s);
  expect_fair_share(h, n);
}

// A 500 kbps line with CAN arbitration (lowest ID first) and a controller
// queue of 4 frames, at a pacing the line can carry (2 frames of at most 135
// bits per hand per interval). Low IDs win arbitration, yet every hand gets
// its share because the scheduler never asks more of the line than it carries.
TEST_P(BusSchedulerFairness, EveryHandGetsItsShareOnAPacedCanLine) {
  const int n = GetParam();
  auto options = test_options();
  const auto exchange = std::chrono::microseconds(2 * 135 * 1'000'000 / 500'000);
  options.command_interval = std::max<Duration>(20ms, 2 * n * exchange);
  options.poll_interval_idle = 0ms;
  options.poll_interval_moving = 0ms;
  sim::SimBusOptions line;
  line.bit_rate = 500'000;
  line.bits_per_frame = 135;
  line.tx_queue_length = 4;
  SchedulerHarness h(sim_hands(ids_1_to(n)), configs(ids_1_to(n)), options, line);
  h.run_for(5s);
  expect_fair_share(h, n);
  EXPECT_EQ(h.scheduler->counters().timeouts, 0u);
}

// The same line with no pacing at all: the scheduler's line budget keeps the
// offered load below what the line carries, so arbitration (lowest ID first)
// cannot starve the highest IDs.
TEST_P(BusSchedulerFairness, EveryHandGetsItsShareOnAnUnpacedCanLine) {
  const int n = GetParam();
  auto options = test_options();
  options.command_interval = 0ms;
  options.poll_interval_idle = 0ms;
  options.poll_interval_moving = 0ms;
  sim::SimBusOptions line;
  line.bit_rate = 500'000;
  line.bits_per_frame = 135;
  line.tx_queue_length = 4;
  SchedulerHarness h(sim_hands(ids_1_to(n)), configs(ids_1_to(n)), options, line);
  h.run_for(5s);
  expect_fair_share(h, n);
  EXPECT_EQ(h.scheduler->counters().timeouts, 0u);
}

TEST(BusSchedulerScheduling, WithoutTheLineBudgetHighIdsStarveOnASaturatedCanLine) {
  // Why the budget exists: the same unpaced load with the limit switched off.
  auto options = test_options();
  options.command_interval = 0ms;
  options.poll_interval_idle = 0ms;
  options.poll_interval_moving = 0ms;
  options.max_line_load = 0.0;
  sim::SimBusOptions line;
  line.bit_rate = 500'000;
  line.bits_per_frame = 135;
  line.tx_queue_length = 4;
  SchedulerHarness h(sim_hands(ids_1_to(8)), configs(ids_1_to(8)), options, line);
  h.run_for(3s);
  EXPECT_GT(h.scheduler->counters().timeouts, 0u);
}

INSTANTIATE_TEST_SUITE_P(Hands, BusSchedulerFairness, ::testing::Values(1, 8, 64));

TEST(BusSchedulerScheduling, ASilentHandDoesNotDelayTheOthers) {
  SchedulerHarness h(sim_hands({1, 2, 3}), configs({1, 2, 3}));
  h.bring_up({1, 2, 3});
  h.sim_bus().with_hand(2, [](sim::SimHand& hand) { hand.set_muted(true); });
  // Hand 2 times out again and again; hands 1 and 3 answer every command.
  int ok_count = 0;
  for (int i = 0; i < 20; ++i) {
    h.scheduler->submit(2, read(reg::kPosition), [](const CommandResult&) {});
    auto r1 = h.call(1, move(i % 2 == 0 ? 20 : 80));
    auto r3 = h.call(3, read(reg::kPosition));
    ok_count += (r1 && r1->ok()) + (r3 && r3->ok());
  }
  EXPECT_EQ(ok_count, 40);
  EXPECT_FALSE(h.state(2)->online);
}

TEST(BusSchedulerScheduling, AFullControllerQueueDelaysFramesButLosesNone) {
  SchedulerHarness h(sim_hands({1, 2}), configs({1, 2}));
  h.bring_up({1, 2});
  h.recorder().refuse_next_sends(5);
  const auto r1 = h.call(1, read(reg::kFirmwareVersion));
  const auto r2 = h.call(2, read(reg::kFirmwareVersion));
  ASSERT_TRUE(r1 && r2);
  EXPECT_TRUE(r1->ok());
  EXPECT_TRUE(r2->ok());
  EXPECT_EQ(h.scheduler->counters().timeouts, 0u);
}

}  // namespace
}  // namespace dh3::hand::test
