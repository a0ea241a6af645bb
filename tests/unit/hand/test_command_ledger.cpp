// A hand's commands from their arrival to their one result: a stop first, a
// newer motion superseding the queued ones of its axes, a command's own
// timeout, the waiters, and a failing group member abandoning its group.

#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "command_ledger.hpp"
#include "dh3/hand/group_release.hpp"

namespace dh3::hand {
namespace {

using namespace std::chrono_literals;
namespace reg = protocol::reg;

class Silent final : public HandObserver {
 public:
  void on_state(const HandState&) override {}
  void on_fresh(const HandState&) override {}
  void on_event(const HandEvent&) override {}
  void on_batch_end(std::uint8_t) override {}
  void on_link(bus::LinkState) override {}
};

class CommandLedgerTest : public ::testing::Test {
 protected:
  CommandLedgerTest() { state_.can_id = 3; }

  /// A command named `tag` in the results; counted in `queued_` as submit() does.
  DriverJob job(const std::string& tag, CommandKind kind, std::int32_t value = 0) {
    DriverJob j;
    j.command.kind = kind;
    j.command.value = value;
    j.submitted = clock_.now();
    j.done = [this, tag](const CommandResult& r) {
      results_.push_back(tag + " " + std::string(r ? "ok" : to_string(r.error())));
    };
    return j;
  }
  void add(DriverJob j) {
    queued_.fetch_add(1);
    ledger_.add(std::move(j));
  }
  /// The results delivered since the last call, in order.
  std::vector<std::string> results() {
    outbox_.deliver(state_, clock_.now());
    return std::exchange(results_, {});
  }
  /// Tags of the queued commands, in the order they would be sent.
  std::vector<std::string> drain() {
    while (auto next = ledger_.take_next(clock_.now())) next->done(CommandSuccess{});
    std::vector<std::string> order = std::exchange(results_, {});
    for (std::string& tag : order) tag.erase(tag.size() - 3);  // " ok"
    return order;
  }
  std::uint64_t counted() const {
    HandMetrics metrics;
    counters_.snapshot(metrics);
    std::uint64_t total = 0;
    for (const CommandTally& tally : metrics.commands) total += tally.count;
    return total;
  }

  FakeClock clock_;
  Silent observer_;
  HandRoster roster_{{{3, "left"}}};
  BusLatencyCounters latency_;
  HandOutbox outbox_{observer_, roster_, latency_, 500ms, false};
  HandCounters counters_;
  std::atomic<int> queued_{0};
  CommandLedger ledger_{queued_, counters_, outbox_, "can0/3 (left)"};
  HandState state_;
  std::vector<std::string> results_;
};

using Results = std::vector<std::string>;

TEST_F(CommandLedgerTest, CommandsGoInOrderAndAStopGoesFirst) {
  add(job("read", CommandKind::read_register));
  add(job("force", CommandKind::set_closing_force, 50));
  add(job("stop", CommandKind::stop));
  EXPECT_EQ(queued_.load(), 3);
  EXPECT_TRUE(ledger_.has_commands());
  EXPECT_EQ(drain(), (Results{"stop", "read", "force"}));
  EXPECT_EQ(queued_.load(), 0);
  EXPECT_FALSE(ledger_.has_commands());
}

TEST_F(CommandLedgerTest, ANewerMotionSupersedesTheQueuedOnesOfItsAxis) {
  add(job("move 1", CommandKind::move_to, 100));
  add(job("rotate", CommandKind::rotate_to, 30));
  add(job("move 2", CommandKind::move_to, 200));
  EXPECT_EQ(results(), (Results{"move 1 cancelled"}));
  EXPECT_EQ(queued_.load(), 2);
  EXPECT_EQ(drain(), (Results{"rotate", "move 2"}));
}

TEST_F(CommandLedgerTest, AStopCancelsEveryMotionNotYetUnderWay) {
  add(job("grasp", CommandKind::grasp, 50));
  ledger_.start(ActiveJob{*ledger_.take_next(clock_.now()), first_step(CommandKind::grasp)});
  add(job("rotate", CommandKind::rotate_to, 30));
  add(job("read", CommandKind::read_register));
  add(job("stop", CommandKind::stop));
  // The grasp's force write went, not its motion: it is over too.
  EXPECT_EQ(results(), (Results{"rotate cancelled", "grasp cancelled"}));
  EXPECT_EQ(ledger_.active(), nullptr);
  EXPECT_EQ(drain(), (Results{"stop", "read"}));
}

TEST_F(CommandLedgerTest, AMotionUnderWayIsNotTakenBack) {
  add(job("move", CommandKind::move_to, 100));
  ledger_.start(ActiveJob{*ledger_.take_next(clock_.now()), SingleFrame{}});
  ledger_.active()->motion_sent = true;
  add(job("stop", CommandKind::stop));
  EXPECT_TRUE(results().empty());
  ASSERT_NE(ledger_.active(), nullptr);
  ledger_.finish_active(CommandSuccess{100, GraspOutcome::none});
  EXPECT_EQ(results(), (Results{"move ok"}));
  EXPECT_EQ(ledger_.active(), nullptr);
}

TEST_F(CommandLedgerTest, AQueuedCommandPastItsOwnTimeoutEndsWithTimeout) {
  DriverJob patient = job("patient", CommandKind::read_register);
  DriverJob hasty = job("hasty", CommandKind::read_register);
  hasty.command.timeout = 100ms;
  add(std::move(hasty));
  add(std::move(patient));
  EXPECT_EQ(ledger_.next_deadline(), clock_.now() + 100ms);
  clock_.advance(100ms - 1ns);
  ledger_.expire_queued(clock_.now());
  EXPECT_TRUE(results().empty());
  clock_.advance(1ns);
  ledger_.expire_queued(clock_.now());
  EXPECT_EQ(results(), (Results{"hasty timeout"}));
  EXPECT_EQ(queued_.load(), 1);
  EXPECT_EQ(ledger_.next_deadline(), std::nullopt);
}

TEST_F(CommandLedgerTest, TakingTheNextCommandSkipsTheTimedOutOnes) {
  DriverJob hasty = job("hasty", CommandKind::read_register);
  hasty.command.timeout = 10ms;
  add(std::move(hasty));
  add(job("patient", CommandKind::read_register));
  clock_.advance(10ms);
  const auto next = ledger_.take_next(clock_.now());
  ASSERT_TRUE(next.has_value());
  EXPECT_EQ(results(), (Results{"hasty timeout"}));
  EXPECT_EQ(queued_.load(), 0);
  EXPECT_FALSE(ledger_.take_next(clock_.now()).has_value());
}

TEST_F(CommandLedgerTest, AnEchoedCommandWaitsAndANewerOneOfItsKindCancelsIt) {
  add(job("release 1", CommandKind::release, 1000));
  ledger_.start(ActiveJob{*ledger_.take_next(clock_.now()), SingleFrame{}});
  ledger_.active_waits_for_motion(clock_.now() + 10s, 1);
  EXPECT_EQ(ledger_.active(), nullptr);
  ASSERT_NE(ledger_.motion_waiter(), nullptr);
  EXPECT_EQ(ledger_.motion_waiter()->epoch, 1u);
  EXPECT_EQ(ledger_.next_deadline(), clock_.now() + 10s);

  add(job("release 2", CommandKind::release, 900));  // a finger motion: the waiter ends
  EXPECT_EQ(results(), (Results{"release 1 cancelled"}));
  ledger_.start(ActiveJob{*ledger_.take_next(clock_.now()), SingleFrame{}});
  ledger_.active_waits_for_motion(clock_.now() + 5s, 2);

  add(job("init", CommandKind::initialize));
  ledger_.start(ActiveJob{*ledger_.take_next(clock_.now()), first_step(CommandKind::initialize)});
  ledger_.active_waits_for_init(clock_.now() + 15s);
  ASSERT_NE(ledger_.init_waiter(), nullptr);
  EXPECT_EQ(ledger_.next_deadline(), clock_.now() + 5s);
  ledger_.finish_motion_waiter(CommandSuccess{900, GraspOutcome::none});
  ledger_.finish_init_waiter(CommandSuccess{1, GraspOutcome::none});
  EXPECT_EQ(results(), (Results{"release 2 ok", "init ok"}));
  EXPECT_EQ(ledger_.next_deadline(), std::nullopt);
}

TEST_F(CommandLedgerTest, EverythingHeldFailsWithTheSameErrorAndIsCounted) {
  add(job("init", CommandKind::initialize));
  ledger_.start(ActiveJob{*ledger_.take_next(clock_.now()), first_step(CommandKind::initialize)});
  ledger_.active_waits_for_init(clock_.now() + 15s);
  add(job("grasp", CommandKind::grasp, 50));
  ledger_.start(ActiveJob{*ledger_.take_next(clock_.now()), first_step(CommandKind::grasp)});
  ledger_.active_waits_for_motion(clock_.now() + 10s, 1);
  add(job("read", CommandKind::read_register));
  ledger_.start(ActiveJob{*ledger_.take_next(clock_.now()), SingleFrame{}});
  add(job("force", CommandKind::set_opening_force, 40));
  ledger_.fail_everything(CommandError::bus_down);
  EXPECT_EQ(results(),
            (Results{"read bus down", "force bus down", "init bus down", "grasp bus down"}));
  EXPECT_EQ(queued_.load(), 0);
  EXPECT_FALSE(ledger_.has_commands());
  EXPECT_EQ(ledger_.init_waiter(), nullptr);
  EXPECT_EQ(ledger_.motion_waiter(), nullptr);
  EXPECT_EQ(counted(), 4u);
}

TEST_F(CommandLedgerTest, AFailingGroupMemberAbandonsItsGroup) {
  auto group = std::make_shared<GroupRelease>(2, Duration::zero(), clock_.now() + 1s);
  DriverJob member = job("member", CommandKind::move_to, 100);
  member.command.group = group;
  add(std::move(member));
  add(job("newer", CommandKind::move_to, 200));  // supersedes the member
  EXPECT_EQ(results(), (Results{"member cancelled"}));
  EXPECT_EQ(group->verdict(clock_.now()), GroupRelease::Verdict::abandoned);
  EXPECT_EQ(group->abandoned_because(), "can0/3 (left): move ended cancelled");
}

TEST_F(CommandLedgerTest, ASucceedingGroupMemberLeavesItsGroupAlone) {
  auto group = std::make_shared<GroupRelease>(2, Duration::zero(), clock_.now() + 1s);
  DriverJob member = job("member", CommandKind::move_to, 100);
  member.command.group = group;
  add(std::move(member));
  ledger_.start(ActiveJob{*ledger_.take_next(clock_.now()), SingleFrame{}});
  ledger_.finish_active(CommandSuccess{100, GraspOutcome::none});
  EXPECT_EQ(results(), (Results{"member ok"}));
  EXPECT_EQ(group->verdict(clock_.now()), GroupRelease::Verdict::hold);
}

}  // namespace
}  // namespace dh3::hand
