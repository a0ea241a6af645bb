// What BusScheduler::metrics() reports: each command counted once under its
// type and result, timeouts and retries on the hand that caused them, one
// round-trip observation per matched reply, reconnects, and the line load.

#include <gtest/gtest.h>

#include <numeric>

#include "scheduler_harness.hpp"

namespace dh3::hand::test {
namespace {

const HandMetrics* hand_of(const BusMetrics& bus, std::uint8_t id) {
  for (const auto& hand : bus.hands) {
    if (hand.can_id == id) return &hand;
  }
  return nullptr;
}

/// How many commands of this type ended with this result (nullopt: OK).
std::uint64_t tally(const BusMetrics& bus, std::uint8_t id, CommandKind kind,
                    std::optional<CommandError> error, protocol::Register reg = {}) {
  const HandMetrics* hand = hand_of(bus, id);
  if (!hand) return 0;
  std::uint64_t count = 0;
  for (const auto& t : hand->commands) {
    if (t.kind == kind && t.error == error && t.reg == reg) count += t.count;
  }
  return count;
}

std::uint64_t all_commands(const BusMetrics& bus, std::uint8_t id) {
  const HandMetrics* hand = hand_of(bus, id);
  if (!hand) return 0;
  return std::accumulate(hand->commands.begin(), hand->commands.end(), std::uint64_t{0},
                         [](std::uint64_t sum, const CommandTally& t) { return sum + t.count; });
}

TEST(BusSchedulerMetrics, EachCommandCountsOnceUnderItsTypeAndResult) {
  SchedulerHarness h(sim_hands({1, 2}), configs({1, 2}));
  ASSERT_TRUE(h.run_until([&] { return h.state(1) && h.state(1)->online; }));

  // Motion before initialization is refused by the driver.
  const auto early = h.call(1, move(40));
  ASSERT_TRUE(early);
  EXPECT_EQ(early->error(), CommandError::not_initialized);
  h.bring_up({1, 2});
  ASSERT_TRUE(h.call(1, move(40)).value().ok());
  ASSERT_TRUE(h.call(1, move(60)).value().ok());
  ASSERT_TRUE(h.call(1, read(reg::kPosition)).value().ok());
  ASSERT_TRUE(h.call(1, write(reg::kInitFeedback, 0)).value().ok());
  // Refused before it is queued.
  EXPECT_EQ(h.call(1, move(300)).value().error(), CommandError::invalid_argument);

  const auto m = h.scheduler->metrics();
  EXPECT_EQ(m.bus, "bus0");
  EXPECT_EQ(tally(m, 1, CommandKind::initialize, std::nullopt), 1u);
  EXPECT_EQ(tally(m, 1, CommandKind::move_to, std::nullopt), 2u);
  EXPECT_EQ(tally(m, 1, CommandKind::move_to, CommandError::not_initialized), 1u);
  EXPECT_EQ(tally(m, 1, CommandKind::move_to, CommandError::invalid_argument), 1u);
  EXPECT_EQ(tally(m, 1, CommandKind::read_register, std::nullopt), 1u);
  EXPECT_EQ(tally(m, 1, CommandKind::write_register, std::nullopt, reg::kInitFeedback), 1u);
  EXPECT_EQ(all_commands(m, 1), 7u);
  // Hand 2 only initialized.
  EXPECT_EQ(tally(m, 2, CommandKind::initialize, std::nullopt), 1u);
  EXPECT_EQ(all_commands(m, 2), 1u);
  ASSERT_TRUE(hand_of(m, 1)->online.has_value());
  EXPECT_TRUE(*hand_of(m, 1)->online);
}

TEST(BusSchedulerMetrics, CommandsToAHandThatDoesNotExistGrowNoHandsFigures) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  const auto result = h.call(9, read(reg::kPosition));
  ASSERT_TRUE(result);
  EXPECT_EQ(result->error(), CommandError::unknown_hand);
  const auto m = h.scheduler->metrics();
  EXPECT_EQ(hand_of(m, 9), nullptr);
  ASSERT_EQ(m.hands.size(), 1u);
  EXPECT_EQ(m.hands[0].can_id, 1);
}

TEST(BusSchedulerMetrics, AMutedHandCountsTimeoutsAndRetriesOnItselfOnly) {
  SchedulerHarness h(sim_hands({1, 2}), configs({1, 2}));
  h.bring_up({1, 2});
  h.sim_bus().with_hand(1, [](sim::SimHand& hand) { hand.set_muted(true); });
  const auto result = h.call(1, read(reg::kFirmwareVersion));
  ASSERT_TRUE(result);
  EXPECT_EQ(result->error(), CommandError::timeout);

  const auto m = h.scheduler->metrics();
  const HandMetrics* muted = hand_of(m, 1);
  const HandMetrics* fine = hand_of(m, 2);
  ASSERT_TRUE(muted && fine);
  // The read was sent 1 + max_retries times, each unanswered.
  EXPECT_GE(muted->retries, static_cast<std::uint64_t>(test_options().max_retries));
  EXPECT_GE(muted->timeouts, static_cast<std::uint64_t>(test_options().max_retries + 1));
  EXPECT_EQ(tally(m, 1, CommandKind::read_register, CommandError::timeout), 1u);
  EXPECT_EQ(fine->timeouts, 0u);
  EXPECT_EQ(fine->retries, 0u);
  // The bus's totals are the hands' sums.
  EXPECT_EQ(m.counters.timeouts, muted->timeouts);
  EXPECT_EQ(m.counters.retries, muted->retries);
  // It went offline after the timeouts in a row.
  EXPECT_FALSE(hand_of(m, 1)->online.value_or(true));
}

TEST(BusSchedulerMetrics, RoundTripIsObservedOncePerMatchedReply) {
  auto sim = sim_hands({1});
  sim[0].reply_delay = 3ms;
  SchedulerHarness h(sim, configs({1}));
  ASSERT_TRUE(h.run_until([&] { return h.recorder().received >= 20; }));
  // Nothing in flight: every frame sent has been answered.
  ASSERT_TRUE(h.run_until([&] { return h.recorder().received == h.recorder().sent.size(); }));

  const auto m = h.scheduler->metrics();
  const HandMetrics* hand = hand_of(m, 1);
  ASSERT_TRUE(hand);
  EXPECT_EQ(m.counters.unexpected_frames, 0u);
  EXPECT_EQ(hand->round_trip.total(), h.recorder().received);
  // A 3 ms reply (plus at most the 1 ms step) lands in the 5 ms bucket.
  const auto five_ms =
      static_cast<std::size_t>(std::find(kRoundTripBuckets.begin(), kRoundTripBuckets.end(), 5ms) -
                               kRoundTripBuckets.begin());
  EXPECT_EQ(hand->round_trip.counts[five_ms], hand->round_trip.total());
  EXPECT_GE(hand->round_trip.sum_seconds, 0.003 * static_cast<double>(hand->round_trip.total()));
  EXPECT_LE(hand->round_trip.sum_seconds, 0.005 * static_cast<double>(hand->round_trip.total()));
}

TEST(BusSchedulerMetrics, LinkDownAndUpCountsOneReconnectAndBusDownCommands) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.bring_up({1});
  EXPECT_EQ(h.scheduler->metrics().counters.reconnects, 0u);
  EXPECT_TRUE(h.scheduler->metrics().link_up);

  h.sim_bus().set_link_up(false);
  ASSERT_TRUE(h.run_until([&] { return h.scheduler->link_state() == bus::LinkState::down; }));
  EXPECT_EQ(h.call(1, read(reg::kPosition)).value().error(), CommandError::bus_down);
  EXPECT_FALSE(h.scheduler->metrics().link_up);

  h.sim_bus().set_link_up(true);
  ASSERT_TRUE(h.run_until([&] { return h.state(1)->online; }));
  const auto m = h.scheduler->metrics();
  EXPECT_EQ(m.counters.reconnects, 1u);
  EXPECT_TRUE(m.link_up);
  EXPECT_EQ(tally(m, 1, CommandKind::read_register, CommandError::bus_down), 1u);
}

TEST(BusSchedulerMetrics, LineLoadFollowsTheFramesOfTheLastSecondsWhenTheBitRateIsKnown) {
  sim::SimBusOptions line;
  line.bit_rate = 125'000;
  SchedulerHarness h(sim_hands({1}), configs({1}), test_options(), line);
  EXPECT_EQ(h.scheduler->metrics().bit_rate, 125'000u);
  h.run_for(7s);
  const auto busy = h.scheduler->metrics();
  ASSERT_TRUE(busy.line_load_percent.has_value());
  EXPECT_GT(busy.recent_frames_per_second, 0.0);
  EXPECT_DOUBLE_EQ(*busy.line_load_percent,
                   100.0 * busy.recent_frames_per_second * kBitsPerFrame / 125'000.0);
  // The idle poll (5 reads and replies every 500 ms) is about 20 frames a second.
  EXPECT_GT(busy.recent_frames_per_second, 10.0);
  EXPECT_LT(busy.recent_frames_per_second, 40.0);

  // Unplugged: after a full window without replies only the probes remain,
  // one every offline_probe_interval (500 ms).
  h.sim_bus().remove_hand(1);
  h.run_for(8s);
  EXPECT_LE(h.scheduler->metrics().recent_frames_per_second, 2.0);
  EXPECT_LT(h.scheduler->metrics().recent_frames_per_second, busy.recent_frames_per_second / 4.0);
}

TEST(BusSchedulerMetrics, ABusWithoutAKnownBitRateHasNoLoadFigure) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.run_for(2s);
  const auto m = h.scheduler->metrics();
  EXPECT_EQ(m.bit_rate, 0u);
  EXPECT_FALSE(m.line_load_percent.has_value());
  EXPECT_GT(m.recent_frames_per_second, 0.0);
  EXPECT_GT(m.counters.frames_sent, 0u);
  EXPECT_GT(m.counters.frames_received, 0u);
}

}  // namespace
}  // namespace dh3::hand::test
