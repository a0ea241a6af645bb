// What goes wrong on a real bus: lost replies (retries), silent hands
// (timeouts, offline, back online), link loss with commands pending, stray and
// corrupted frames, and shutdown. Every command still ends in one result.

#include <gtest/gtest.h>

#include "unit/hand/scheduler_harness.hpp"

namespace dh3::hand::test {
namespace {

using protocol::Message;

TEST(BusSchedulerFaults, ReadsAreRetriedAndSucceedWhenTheHandAnswersAgain) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.bring_up({1});
  h.sim_bus().with_hand(1, [](sim::SimHand& hand) { hand.set_muted(true); });
  std::optional<CommandResult> result;
  h.scheduler->submit(1, read(reg::kFirmwareVersion), [&](const CommandResult& r) { result = r; });
  // The first try times out (100 ms); the hand answers the re-send.
  ASSERT_TRUE(h.run_until([&] { return h.scheduler->counters().retries >= 1; }));
  h.sim_bus().with_hand(1, [](sim::SimHand& hand) { hand.set_muted(false); });
  ASSERT_TRUE(h.run_until([&] { return result.has_value(); }));
  ASSERT_TRUE(result->ok()) << to_string(result->error());
  EXPECT_EQ(result->value().value, 0x04010200);
}

TEST(BusSchedulerFaults, ASilentHandTimesOutAfterBoundedRetriesAndGoesOffline) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.bring_up({1});
  h.sim_bus().with_hand(1, [](sim::SimHand& hand) { hand.set_muted(true); });
  const std::size_t before = h.sent_to(1, reg::kFirmwareVersion).size();
  const auto result = h.call(1, read(reg::kFirmwareVersion));
  ASSERT_TRUE(result);
  EXPECT_EQ(result->error(), CommandError::timeout);
  // One try and max_retries (2) re-sends, no more.
  EXPECT_EQ(h.sent_to(1, reg::kFirmwareVersion).size() - before, 3u);
  ASSERT_TRUE(h.run_until([&] { return !h.state(1)->online; }));
  EXPECT_EQ(h.observer.events_of(EventKind::offline, 1).size(), 1u);
  EXPECT_EQ(h.state(1)->last_error, CommandError::timeout);
}

TEST(BusSchedulerFaults, InitializationIsNotResentAfterTheHandEchoedIt) {
  auto sim = sim_hands({1});
  sim[0].init_time = 1h;
  auto options = test_options();
  options.init_timeout = 1s;
  SchedulerHarness h(sim, configs({1}), options);
  h.run_until([&] { return h.state(1) && h.state(1)->online; });
  (void)h.call(1, cmd(CommandKind::initialize));
  std::size_t init_writes = 0;
  for (const auto& s : h.sent_to(1, reg::kInitialize)) {
    init_writes += s.message.access == protocol::Access::write;
  }
  EXPECT_EQ(init_writes, 1u);
}

TEST(BusSchedulerFaults, AnOfflineHandIsProbedAndComesBackWithItsStateReadAfresh) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.bring_up({1});
  ASSERT_TRUE(h.call(1, cmd(CommandKind::set_closing_force, 70))->ok());
  h.sim_bus().with_hand(1, [](sim::SimHand& hand) { hand.set_muted(true); });
  ASSERT_TRUE(h.run_until([&] { return !h.state(1)->online; }));
  // Meanwhile someone power-cycles it and it answers again.
  h.sim_bus().with_hand(1, [&](sim::SimHand& hand) {
    hand.reboot(h.clock.now());
    hand.set_muted(false);
  });
  ASSERT_TRUE(h.run_until([&] { return h.state(1)->online; }));
  // Power-on values, read afresh rather than remembered.
  ASSERT_TRUE(h.run_until([&] { return h.state(1)->closing_force == 50; }));
  EXPECT_FALSE(h.state(1)->initialized);
  EXPECT_EQ(h.observer.events_of(EventKind::online, 1).size(), 2u);
  EXPECT_TRUE(h.call(1, cmd(CommandKind::initialize))->ok());
}

TEST(BusSchedulerFaults, AConfiguredHandThatNeverAnswersSaysSoUntilItDoes) {
  SchedulerHarness h(sim_hands({1, 2}), configs({1, 2}));
  h.sim_bus().with_hand(2, [](sim::SimHand& hand) { hand.set_muted(true); });
  ASSERT_TRUE(h.run_until([&] { return h.state(1) && h.state(1)->online; }));
  ASSERT_TRUE(h.run_until([&] { return h.state(2) && h.state(2)->last_error.has_value(); }));
  EXPECT_FALSE(h.state(2)->online);
  EXPECT_EQ(h.state(2)->read_at, TimePoint{});
  EXPECT_NE(h.state(2)->last_error_message.find("never answered"), std::string::npos)
      << h.state(2)->last_error_message;
  h.sim_bus().with_hand(2, [](sim::SimHand& hand) { hand.set_muted(false); });
  ASSERT_TRUE(h.run_until([&] { return h.state(2)->online; }));
  EXPECT_FALSE(h.state(2)->last_error.has_value()) << h.state(2)->last_error_message;
}

TEST(BusSchedulerFaults, LinkLossEndsEveryPendingCommandWithBusDownAndRecovers) {
  auto sim = sim_hands({1, 2});
  sim[0].reply_delay = 50ms;  // so that commands are pending when the link drops
  SchedulerHarness h(sim, configs({1, 2}));
  h.bring_up({1, 2});
  std::vector<std::optional<CommandResult>> results(4);
  h.scheduler->submit(1, read(reg::kPosition), [&](const CommandResult& r) { results[0] = r; });
  h.scheduler->submit(1, cmd(CommandKind::set_closing_force, 30),
                      [&](const CommandResult& r) { results[1] = r; });
  h.scheduler->submit(2, grasp(40), [&](const CommandResult& r) { results[2] = r; });
  h.run_for(5ms);
  h.sim_bus().set_link_up(false);
  ASSERT_TRUE(h.run_until([&] { return results[0] && results[1] && results[2]; }, 1s));
  for (int i = 0; i < 3; ++i) EXPECT_EQ(results[i]->error(), CommandError::bus_down) << i;
  EXPECT_EQ(h.scheduler->link_state(), bus::LinkState::down);
  EXPECT_FALSE(h.state(1)->online);
  EXPECT_FALSE(h.state(2)->online);
  ASSERT_FALSE(h.observer.links.empty());
  EXPECT_EQ(h.observer.links.back(), bus::LinkState::down);
  // While down, new commands end at once with BUS_DOWN.
  h.scheduler->submit(1, read(reg::kPosition), [&](const CommandResult& r) { results[3] = r; });
  h.run_for(5ms);
  ASSERT_TRUE(results[3]);
  EXPECT_EQ(results[3]->error(), CommandError::bus_down);

  h.sim_bus().set_link_up(true);
  ASSERT_TRUE(h.run_until([&] { return h.state(1)->online && h.state(2)->online; }));
  EXPECT_EQ(h.observer.links.back(), bus::LinkState::up);
  const auto again = h.call(2, read(reg::kFirmwareVersion));
  ASSERT_TRUE(again && again->ok());
}

TEST(BusSchedulerFaults, StrayFramesAreCountedAndNeverTakenForAReply) {
  auto sim = sim_hands({1});
  sim[0].reply_delay = 30ms;
  SchedulerHarness h(sim, configs({1}));
  h.bring_up({1});
  const auto unexpected_before = h.scheduler->counters().unexpected_frames;
  std::optional<CommandResult> result;
  h.scheduler->submit(1, read(reg::kFirmwareVersion), [&](const CommandResult& r) { result = r; });
  ASSERT_TRUE(h.run_until([&] {
    const auto sent = h.sent_to(1, reg::kFirmwareVersion);
    return !sent.empty() && h.clock.now() - sent.back().at >= 5ms;
  }));
  // While the read waits: a frame of another register, one from an unknown
  // hand, and one of the same register from another hand.
  h.recorder().inject(protocol::make_read(1, reg::kRotation));
  h.recorder().inject(protocol::make_read(9, reg::kFirmwareVersion));
  h.recorder().inject(Message{2, reg::kFirmwareVersion, protocol::Access::read, 0, 7});
  ASSERT_TRUE(h.run_until([&] { return result.has_value(); }));
  ASSERT_TRUE(result->ok());
  EXPECT_EQ(result->value().value, 0x04010200);
  EXPECT_EQ(h.scheduler->counters().unexpected_frames - unexpected_before, 3u);
}

TEST(BusSchedulerFaults, ARefusedWriteIsAFailureNotASuccess) {
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.bring_up({1});
  // The hand's reply is corrupted: its echo differs from what was written.
  h.sim_bus().with_hand(1, [](sim::SimHand& hand) { hand.corrupt_next_replies(1); });
  const auto result = h.call(1, cmd(CommandKind::set_closing_force, 40));
  ASSERT_TRUE(result);
  ASSERT_FALSE(result->ok());
  EXPECT_EQ(result->error(), CommandError::failed);
  EXPECT_FALSE(h.observer.events_of(EventKind::fault, 1).empty());
  EXPECT_FALSE(h.state(1)->last_error_message.empty());
}

TEST(BusSchedulerFaults, StopEndsPendingCommandsCancelledAndReportsHandsOffline) {
  auto sim = sim_hands({1});
  sim[0].reply_delay = 50ms;
  SchedulerHarness h(sim, configs({1}));
  h.bring_up({1});
  std::optional<CommandResult> pending;
  std::optional<CommandResult> queued;
  h.scheduler->submit(1, move(10), [&](const CommandResult& r) { pending = r; });
  h.scheduler->submit(1, read(reg::kRotation), [&](const CommandResult& r) { queued = r; });
  h.run_for(5ms);
  h.scheduler->stop();
  ASSERT_TRUE(pending && queued);
  EXPECT_EQ(pending->error(), CommandError::cancelled);
  EXPECT_EQ(queued->error(), CommandError::cancelled);
  EXPECT_FALSE(h.state(1)->online);
  std::optional<CommandResult> late;
  h.scheduler->submit(1, read(reg::kRotation), [&](const CommandResult& r) { late = r; });
  ASSERT_TRUE(late);
  EXPECT_EQ(late->error(), CommandError::cancelled);
}

TEST(BusSchedulerFaults, EveryCommandEndsExactlyOnceUnderMixedFaults) {
  SchedulerHarness h(sim_hands({1, 2, 3}), configs({1, 2, 3}));
  h.bring_up({1, 2, 3});
  int completions = 0;
  constexpr int kCommands = 300;
  for (int i = 0; i < kCommands; ++i) {
    const auto id = static_cast<std::uint8_t>(1 + i % 3);
    const Command c = i % 4 == 0   ? move(i % 101)
                      : i % 4 == 1 ? read(reg::kPosition)
                      : i % 4 == 2 ? cmd(CommandKind::set_opening_force, 20 + i % 81)
                                   : grasp(20 + i % 81);
    h.scheduler->submit(id, c, [&](const CommandResult&) { ++completions; });
    if (i == 100) h.sim_bus().with_hand(2, [](sim::SimHand& hand) { hand.set_muted(true); });
    if (i == 150) h.sim_bus().set_link_up(false);
    if (i == 170) h.sim_bus().set_link_up(true);
    if (i == 200)
      h.sim_bus().with_hand(3, [](sim::SimHand& hand) { hand.corrupt_next_replies(5); });
    h.run_for(7ms);
  }
  ASSERT_TRUE(h.run_until([&] { return completions == kCommands; }, 60s))
      << completions << " of " << kCommands << " completed";
  h.run_for(5s);
  EXPECT_EQ(completions, kCommands);  // and the harness checks none completes twice
}

}  // namespace
}  // namespace dh3::hand::test
