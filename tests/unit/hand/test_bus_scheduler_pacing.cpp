// The document's pacing holds for every frame a hand receives, whoever sends it
// and why: discovery probes, the first reads after discovery, initialization,
// commands, polls, offline probes, the reads after a hand comes back or the
// link returns, and frames to ID 0 (which every hand on the bus receives).

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <map>
#include <string>

#include "unit/hand/scheduler_harness.hpp"

namespace dh3::hand::test {
namespace {

/// Every pair of consecutive frames to one hand closer than `interval`, as
/// text. A frame to ID 0 counts as a frame to each of `hands`.
std::vector<std::string> pacing_violations(const RecordingBus& bus,
                                           const std::vector<std::uint8_t>& hands,
                                           Duration interval) {
  std::map<std::uint8_t, const RecordingBus::Sent*> last;
  std::vector<std::string> violations;
  for (const auto& sent : bus.sent) {
    std::vector<std::uint8_t> receivers{sent.message.hand_id};
    if (sent.message.hand_id == 0) receivers = hands;
    for (std::uint8_t id : receivers) {
      if (const auto* previous = last[id]; previous && sent.at - previous->at < interval) {
        violations.push_back(fmt::format(
            "hand {}: {} {} us after {}", id, protocol::describe(sent.message),
            std::chrono::duration_cast<std::chrono::microseconds>(sent.at - previous->at).count(),
            protocol::describe(previous->message)));
      }
      last[id] = &sent;
    }
  }
  return violations;
}

std::string joined(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& line : lines) out += line + "\n";
  return out;
}

/// Steps the harness until the command's result is in, without waiting for it
/// to be the only thing going on.
void submit_and_run(SchedulerHarness& h, std::uint8_t id, Command command) {
  std::optional<CommandResult> result;
  h.scheduler->submit(id, std::move(command), [&](const CommandResult& r) { result = r; });
  ASSERT_TRUE(h.run_until([&] { return result.has_value(); }, 30s));
}

TEST(BusSchedulerPacing, NoHandReceivesTwoFramesCloserThanTheCommandInterval) {
  const std::vector<std::uint8_t> ids{1, 2};
  // Discovered, not configured: the first frames a hand sees are the scan's probe
  // and then the driver's reads of its state.
  SchedulerHarness h(sim_hands(ids), {});
  ASSERT_TRUE(h.run_until(
      [&] {
        auto one = h.state(1);
        auto two = h.state(2);
        return one && one->online && two && two->online;
      },
      5s));
  h.bring_up(ids);

  // Commands of every kind, on both hands at once, with polls in between.
  h.scheduler->submit(2, move(20), [](const CommandResult&) {});
  submit_and_run(h, 1, cmd(CommandKind::set_closing_force, 40));
  submit_and_run(h, 1, move(30));
  h.sim_bus().with_hand(1, [](sim::SimHand& hand) { hand.place_object(60); });
  submit_and_run(h, 1, grasp(50));
  submit_and_run(h, 1, cmd(CommandKind::release, 100));
  submit_and_run(h, 2, cmd(CommandKind::rotate_to, 80));
  h.scheduler->submit(1, move(0), [](const CommandResult&) {});
  h.run_for(30ms);
  submit_and_run(h, 1, cmd(CommandKind::stop));
  submit_and_run(h, 2, read(reg::kFirmwareVersion));
  h.run_for(1s);

  // Hand 1 stops answering until it is offline, then comes back.
  h.sim_bus().with_hand(1, [](sim::SimHand& hand) { hand.set_muted(true); });
  ASSERT_TRUE(h.run_until([&] { return !h.state(1)->online; }, 5s));
  h.run_for(1200ms);  // offline probes
  h.sim_bus().with_hand(1, [](sim::SimHand& hand) { hand.set_muted(false); });
  ASSERT_TRUE(h.run_until([&] { return h.state(1)->online; }, 5s));
  h.run_for(1s);

  // The link drops right after frames went out and returns at once.
  for (int flap = 0; flap < 5; ++flap) {
    const std::size_t before = h.recorder().sent.size();
    ASSERT_TRUE(h.run_until([&] { return h.recorder().sent.size() > before; }, 2s));
    h.sim_bus().set_link_up(false);
    h.run_for(2ms);
    h.sim_bus().set_link_up(true);
    ASSERT_TRUE(h.run_until([&] { return h.state(1)->online && h.state(2)->online; }, 5s));
  }
  h.run_for(1s);

  ASSERT_GT(h.sent_to(1).size(), 50u);
  ASSERT_GT(h.sent_to(2).size(), 50u);
  const auto violations = pacing_violations(h.recorder(), ids, test_options().command_interval);
  EXPECT_TRUE(violations.empty()) << violations.size() << " frames too soon:\n"
                                  << joined(violations);
}

TEST(BusSchedulerPacing, FramesToIdZeroKeepTheIntervalToTheHandThatReceivesThem) {
  // ID 0 reaches whichever hand is there: hand 1, polled and moving meanwhile.
  SchedulerHarness h(sim_hands({1}), configs({1}));
  h.bring_up({1});
  for (int i = 0; i < 5; ++i) {
    h.scheduler->submit(1, move(i % 2 == 0 ? 10 : 90), [](const CommandResult&) {});
    h.run_for(7ms);
    std::optional<CommandResult> id;
    h.scheduler->submit(0, read(reg::kCanId), [&](const CommandResult& r) { id = r; });
    ASSERT_TRUE(h.run_until([&] { return id.has_value(); }, 5s));
    ASSERT_TRUE(id->ok());
    EXPECT_EQ(id->value().value, 1);
  }
  h.run_for(500ms);
  ASSERT_EQ(h.sent_to(0).size(), 5u);
  const auto violations = pacing_violations(h.recorder(), {1}, test_options().command_interval);
  EXPECT_TRUE(violations.empty()) << violations.size() << " frames too soon:\n"
                                  << joined(violations);
}

TEST(BusSchedulerPacing, TheIntervalCountsFromWhenAFrameLeftNotFromWhenTheLoopPassBegan) {
  // Publishing a status takes time (a DDS write on a loaded machine: several
  // milliseconds), and a pass publishes before it sends. Frames must still be
  // 20 ms apart as the hand sees them.
  const std::vector<std::uint8_t> ids{1, 2};
  SchedulerHarness h(sim_hands(ids), configs(ids));
  h.observer.while_publishing = [&h] { h.clock.advance(3ms); };
  h.bring_up(ids);
  submit_and_run(h, 1, move(30));
  submit_and_run(h, 2, cmd(CommandKind::rotate_to, 60));
  submit_and_run(h, 1, grasp(50));
  h.run_for(2s);
  ASSERT_GT(h.recorder().sent.size(), 40u);
  const auto violations = pacing_violations(h.recorder(), ids, test_options().command_interval);
  EXPECT_TRUE(violations.empty()) << violations.size() << " frames too soon:\n"
                                  << joined(violations);
}

TEST(BusSchedulerPacing, AMarginKeepsTheHandsFramesTheIntervalPlusTheMarginApart) {
  // A transfer box behind TCP may deliver one frame late and the next on time:
  // frames leave command_interval + interval_margin apart, so the hand still
  // sees command_interval after a delay up to the margin.
  const std::vector<std::uint8_t> ids{1, 2};
  auto options = test_options();
  options.interval_margin = 3ms;
  SchedulerHarness h(sim_hands(ids), configs(ids), options);
  h.bring_up(ids);
  h.sim_bus().with_hand(1, [](sim::SimHand& hand) { hand.place_object(60); });
  submit_and_run(h, 1, grasp(50));
  submit_and_run(h, 2, move(30));
  submit_and_run(h, 1, cmd(CommandKind::release, 100));
  h.run_for(1s);
  ASSERT_GT(h.sent_to(1).size(), 20u);
  const auto spacing = options.command_interval + 3ms;
  const auto violations = pacing_violations(h.recorder(), ids, spacing);
  EXPECT_TRUE(violations.empty()) << violations.size() << " frames too soon:\n"
                                  << joined(violations);
}

}  // namespace
}  // namespace dh3::hand::test
