// Group commands in the hand layer (group_release.hpp): the members' motion
// frames leave at one instant, back to back, each hand's interval respected;
// a member that fails before the release keeps every frame of the group off
// the bus; members on two buses leave at one common instant.

#include <gtest/gtest.h>

#include <memory>

#include "dh3/hand/group_release.hpp"
#include "unit/hand/scheduler_harness.hpp"

namespace dh3::hand::test {
namespace {

struct Member {
  std::uint8_t id = 0;
  std::optional<CommandResult> result;
};

/// Submits `command` to every hand of `ids` as one group on `h`'s bus.
std::vector<std::shared_ptr<Member>> submit_group(SchedulerHarness& h,
                                                  const std::vector<std::uint8_t>& ids,
                                                  Command command, Duration lead = {}) {
  command.group = std::make_shared<GroupRelease>(ids.size(), lead, h.clock.now() + 5s);
  std::vector<std::shared_ptr<Member>> members;
  for (std::uint8_t id : ids) {
    auto member = std::make_shared<Member>();
    member->id = id;
    members.push_back(member);
    h.scheduler->submit(id, command, [member](const CommandResult& r) { member->result = r; });
  }
  return members;
}

/// The frames that wrote `r` to hand `id`.
std::vector<RecordingBus::Sent> writes_to(const SchedulerHarness& h, std::uint8_t id,
                                          protocol::Register r) {
  std::vector<RecordingBus::Sent> out;
  for (const auto& s : h.sent_to(id, r)) {
    if (s.message.access == protocol::Access::write) out.push_back(s);
  }
  return out;
}

bool all_done(const std::vector<std::shared_ptr<Member>>& members) {
  for (const auto& m : members) {
    if (!m->result) return false;
  }
  return true;
}

/// Where each of `ids`' frames to `r` sits in the bus's send order.
std::vector<std::size_t> send_positions(const RecordingBus& bus, const std::vector<std::uint8_t>& ids,
                                        protocol::Register r) {
  std::vector<std::size_t> positions;
  for (std::size_t i = 0; i < bus.sent.size(); ++i) {
    const auto& m = bus.sent[i].message;
    if (m.reg == r && m.access == protocol::Access::write &&
        std::find(ids.begin(), ids.end(), m.hand_id) != ids.end()) {
      positions.push_back(i);
    }
  }
  return positions;
}

TEST(BusSchedulerGroup, MembersFramesLeaveAtOneInstantBackToBack) {
  const std::vector<std::uint8_t> ids{1, 2, 3, 4};
  SchedulerHarness h(sim_hands(ids), configs(ids));
  h.bring_up(ids);
  h.run_for(200ms);  // polls going on: the members' intervals end at different times

  auto members = submit_group(h, ids, move(30));
  ASSERT_TRUE(h.run_until([&] { return all_done(members); }, 10s));
  for (const auto& m : members) {
    ASSERT_TRUE(m->result->ok()) << "hand " << int(m->id) << ": "
                                 << to_string(m->result->error());
  }
  const auto positions = send_positions(h.recorder(), ids, reg::kPosition);
  ASSERT_EQ(positions.size(), ids.size());
  for (std::size_t k = 1; k < positions.size(); ++k) {
    EXPECT_EQ(positions[k], positions[0] + k) << "another frame went out between the group's";
    EXPECT_EQ(h.recorder().sent[positions[k]].at, h.recorder().sent[positions[0]].at);
  }
  // Each hand's own interval before its group frame was kept.
  for (std::uint8_t id : ids) {
    const auto frames = h.sent_to(id);
    for (std::size_t k = 1; k < frames.size(); ++k) {
      EXPECT_GE(frames[k].at - frames[k - 1].at, 20ms) << "hand " << int(id);
    }
  }
}

TEST(BusSchedulerGroup, MembersFramesGoToTheBusAsOneBurst) {
  const std::vector<std::uint8_t> ids{1, 2, 3, 4};
  SchedulerHarness h(sim_hands(ids), configs(ids));
  h.bring_up(ids);
  h.run_for(200ms);
  auto members = submit_group(h, ids, move(30));
  ASSERT_TRUE(h.run_until([&] { return all_done(members); }, 10s));
  // One call for the four (on SocketCAN one sendmmsg); nothing else is a burst.
  EXPECT_EQ(h.recorder().bursts, std::vector<std::size_t>{4});
}

TEST(BusSchedulerGroup, WhatABurstLeftBehindGoesOutOnceEachAfterIt) {
  const std::vector<std::uint8_t> ids{1, 2, 3, 4};
  SchedulerHarness h(sim_hands(ids), configs(ids));
  h.bring_up(ids);
  h.run_for(200ms);
  h.recorder().limit_next_burst(2);  // the controller's queue takes two
  auto members = submit_group(h, ids, move(30));
  ASSERT_TRUE(h.run_until([&] { return all_done(members); }, 10s));
  for (const auto& m : members) {
    EXPECT_TRUE(m->result->ok()) << "hand " << int(m->id) << ": " << to_string(m->result->error());
  }
  EXPECT_EQ(send_positions(h.recorder(), ids, reg::kPosition).size(), ids.size())
      << "one position write per member, none lost and none twice";
  for (std::uint8_t id : ids) {
    const auto frames = h.sent_to(id);
    for (std::size_t k = 1; k < frames.size(); ++k) {
      EXPECT_GE(frames[k].at - frames[k - 1].at, 20ms) << "hand " << int(id);
    }
  }
}

TEST(BusSchedulerGroup, GroupWaitsUntilEveryMembersIntervalIsClear) {
  const std::vector<std::uint8_t> ids{1, 2};
  SchedulerHarness h(sim_hands(ids), configs(ids));
  h.bring_up(ids);
  h.run_for(100ms);
  // Hand 2 gets a frame now: the group cannot leave before its interval ends.
  h.scheduler->submit(2, read(reg::kFirmwareVersion), [](const CommandResult&) {});
  h.run_for(1ms);
  const auto last_to_two = h.sent_to(2).back().at;
  auto members = submit_group(h, ids, move(50));
  ASSERT_TRUE(h.run_until([&] { return all_done(members); }, 10s));
  const auto one = writes_to(h, 1, reg::kPosition);
  const auto two = writes_to(h, 2, reg::kPosition);
  ASSERT_EQ(one.size(), 1U);
  ASSERT_EQ(two.size(), 1U);
  EXPECT_EQ(one[0].at, two[0].at);
  EXPECT_GE(two[0].at - last_to_two, 20ms);
}

TEST(BusSchedulerGroup, GraspGroupClosesTogetherAfterEachForceWrite) {
  const std::vector<std::uint8_t> ids{1, 2, 3};
  SchedulerHarness h(sim_hands(ids), configs(ids));
  h.bring_up(ids);
  h.sim_bus().with_hand(1, [](sim::SimHand& hand) { hand.place_object(60); });
  auto members = submit_group(h, ids, grasp(50));
  ASSERT_TRUE(h.run_until([&] { return all_done(members); }, 10s));
  for (const auto& m : members) ASSERT_TRUE(m->result->ok());
  EXPECT_EQ(members[0]->result->value().grasp, GraspOutcome::grasped);
  EXPECT_EQ(members[1]->result->value().grasp, GraspOutcome::missed);
  std::vector<TimePoint> closes;
  for (std::uint8_t id : ids) {
    const auto force = writes_to(h, id, reg::kClosingForce);
    const auto close = writes_to(h, id, reg::kPosition);
    ASSERT_FALSE(force.empty());
    ASSERT_EQ(close.size(), 1U);
    EXPECT_LT(force.back().at, close[0].at) << "the force is set before the close";
    closes.push_back(close[0].at);
  }
  EXPECT_EQ(closes[0], closes[1]);
  EXPECT_EQ(closes[0], closes[2]);
}

TEST(BusSchedulerGroup, MemberThatFailsFirstKeepsEveryFrameOfTheGroupOffTheBus) {
  const std::vector<std::uint8_t> ids{1, 2};
  SchedulerHarness h(sim_hands(ids), configs(ids));
  h.bring_up({1});  // hand 2 online but not initialized: its move ends NOT_INITIALIZED
  ASSERT_TRUE(h.run_until([&] { return h.state(2) && h.state(2)->online; }));
  h.run_for(100ms);
  auto members = submit_group(h, ids, move(10));
  ASSERT_TRUE(h.run_until([&] { return all_done(members); }, 10s));
  ASSERT_FALSE(members[1]->result->ok());
  EXPECT_EQ(members[1]->result->error(), CommandError::not_initialized);
  ASSERT_FALSE(members[0]->result->ok());
  EXPECT_EQ(members[0]->result->error(), CommandError::cancelled);
  EXPECT_TRUE(writes_to(h, 1, reg::kPosition).empty());
  EXPECT_TRUE(writes_to(h, 2, reg::kPosition).empty());
  // Hand 1 is polled as before once the group is over.
  const auto before = h.sent_to(1).size();
  h.run_for(1s);
  EXPECT_GT(h.sent_to(1).size(), before);
}

TEST(BusSchedulerGroup, MemberRefusedAtSubmitAbandonsTheGroup) {
  const std::vector<std::uint8_t> ids{1, 2};
  SchedulerHarness h(sim_hands(ids), configs(ids));
  h.bring_up(ids);
  // Hand 9 is not on this bus: refused at once, the group never releases.
  auto members = submit_group(h, {1, 2, 9}, move(10));
  ASSERT_TRUE(h.run_until([&] { return all_done(members); }, 10s));
  EXPECT_EQ(members[2]->result->error(), CommandError::unknown_hand);
  EXPECT_EQ(members[0]->result->error(), CommandError::cancelled);
  EXPECT_EQ(members[1]->result->error(), CommandError::cancelled);
  EXPECT_TRUE(writes_to(h, 1, reg::kPosition).empty());
  EXPECT_TRUE(writes_to(h, 2, reg::kPosition).empty());
}

TEST(BusSchedulerGroup, GroupNotReadyByItsDeadlineIsAbandoned) {
  const std::vector<std::uint8_t> ids{1, 2};
  SchedulerHarness h(sim_hands(ids), configs(ids));
  h.bring_up(ids);
  Command command = move(10);
  // Three members, only two ever submitted: the group cannot be complete.
  command.group = std::make_shared<GroupRelease>(3, Duration{}, h.clock.now() + 1s);
  std::optional<CommandResult> one;
  std::optional<CommandResult> two;
  h.scheduler->submit(1, command, [&](const CommandResult& r) { one = r; });
  h.scheduler->submit(2, command, [&](const CommandResult& r) { two = r; });
  ASSERT_TRUE(h.run_until([&] { return one && two; }, 5s));
  EXPECT_EQ(one->error(), CommandError::cancelled);
  EXPECT_EQ(two->error(), CommandError::cancelled);
  EXPECT_TRUE(writes_to(h, 1, reg::kPosition).empty());
}

TEST(BusSchedulerGroup, MembersOnTwoBusesLeaveAtOneInstant) {
  FakeClock clock;
  RecordingObserver observer_a;
  RecordingObserver observer_b;
  auto make = [&](const char* name, std::uint8_t id, RecordingObserver& observer,
                  RecordingBus*& recorder) {
    auto sim = std::make_unique<sim::SimBus>("sim:test", sim_hands({id}), clock);
    auto recording = std::make_unique<RecordingBus>(std::move(sim), clock);
    recorder = recording.get();
    return std::make_unique<BusScheduler>(name, std::move(recording), configs({id}),
                                          test_options(), clock, observer);
  };
  RecordingBus* bus_a = nullptr;
  RecordingBus* bus_b = nullptr;
  auto a = make("a", 1, observer_a, bus_a);
  auto b = make("b", 2, observer_b, bus_b);
  auto tick = [&] {
    clock.advance(1ms);
    a->step();
    b->step();
  };
  auto run_until = [&](const std::function<bool()>& done) {
    for (int i = 0; i < 20000 && !done(); ++i) tick();
    return done();
  };
  std::optional<CommandResult> init_a;
  std::optional<CommandResult> init_b;
  ASSERT_TRUE(run_until([&] { return a->state()[0].online && b->state()[0].online; }));
  a->submit(1, cmd(CommandKind::initialize), [&](const CommandResult& r) { init_a = r; });
  b->submit(2, cmd(CommandKind::initialize), [&](const CommandResult& r) { init_b = r; });
  ASSERT_TRUE(run_until([&] { return init_a && init_b; }));
  // Bus b is one pass behind bus a; the lead puts the release ahead of both.
  a->submit(1, read(reg::kPosition), [](const CommandResult&) {});
  tick();
  Command command = move(40);
  command.group = std::make_shared<GroupRelease>(2, 3ms, clock.now() + 5s);
  std::optional<CommandResult> one;
  std::optional<CommandResult> two;
  a->submit(1, command, [&](const CommandResult& r) { one = r; });
  b->submit(2, command, [&](const CommandResult& r) { two = r; });
  ASSERT_TRUE(run_until([&] { return one && two; }));
  ASSERT_TRUE(one->ok());
  ASSERT_TRUE(two->ok());
  TimePoint at_a{};
  TimePoint at_b{};
  for (const auto& s : bus_a->sent) {
    if (s.message.reg == reg::kPosition && s.message.access == protocol::Access::write) at_a = s.at;
  }
  for (const auto& s : bus_b->sent) {
    if (s.message.reg == reg::kPosition && s.message.access == protocol::Access::write) at_b = s.at;
  }
  EXPECT_EQ(at_a, at_b);
  EXPECT_EQ(at_a, *command.group->release_at());
}

}  // namespace
}  // namespace dh3::hand::test
