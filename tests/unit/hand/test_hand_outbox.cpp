// What a hand's pass reports, delivered at its end: the state when it changed
// (or read again, now and then), its events, its completions, then the end of
// the batch, in that order.

#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <vector>

#include "hand_outbox.hpp"

namespace dh3::hand {
namespace {

using namespace std::chrono_literals;

constexpr Duration kFresh = 500ms;

/// Every call, in order, as "state 3 seq 1", "fresh 3", "event 3 grasped", "end 3".
class CallLog final : public HandObserver {
 public:
  void on_state(const HandState& s) override {
    calls.push_back("state " + std::to_string(s.can_id) + " seq " + std::to_string(s.sequence));
  }
  void on_fresh(const HandState& s) override {
    calls.push_back("fresh " + std::to_string(s.can_id));
  }
  void on_event(const HandEvent& e) override {
    calls.push_back("event " + std::to_string(e.can_id) + " " + std::string(to_string(e.kind)));
  }
  void on_batch_end(std::uint8_t can_id) override {
    calls.push_back("end " + std::to_string(can_id));
  }
  void on_link(bus::LinkState) override { calls.push_back("link"); }

  std::vector<std::string> take() { return std::exchange(calls, {}); }
  std::vector<std::string> calls;
};

using Calls = std::vector<std::string>;

class HandOutboxTest : public ::testing::Test {
 protected:
  HandOutboxTest() {
    state_.can_id = 3;
    state_.read_at = clock_.now();
  }
  HandEvent event(EventKind kind) const {
    HandEvent e;
    e.kind = kind;
    e.can_id = state_.can_id;
    e.time = clock_.now();
    return e;
  }

  FakeClock clock_;
  CallLog log_;
  HandRoster roster_{{{3, "left"}}};
  BusLatencyCounters latency_;
  HandOutbox outbox_{log_, roster_, latency_, kFresh, false};
  HandState state_;
};

TEST_F(HandOutboxTest, TheFirstDeliveryPublishesTheState) {
  outbox_.deliver(state_, clock_.now());
  EXPECT_EQ(log_.take(), (Calls{"state 3 seq 1", "end 3"}));
  EXPECT_EQ(state_.sequence, 1u);
  EXPECT_EQ(state_.updated_at, clock_.now());
  ASSERT_EQ(roster_.published().size(), 1u);
  EXPECT_EQ(roster_.published()[0].sequence, 1u);
}

TEST_F(HandOutboxTest, AnUnchangedStateIsNotPublishedAgain) {
  outbox_.deliver(state_, clock_.now());
  log_.take();
  clock_.advance(10ms);
  outbox_.deliver(state_, clock_.now());
  EXPECT_TRUE(log_.take().empty());
  EXPECT_EQ(state_.sequence, 1u);
}

TEST_F(HandOutboxTest, AChangedStateIsPublishedWithTheNextSequence) {
  outbox_.deliver(state_, clock_.now());
  log_.take();
  clock_.advance(10ms);
  state_.position = 42;
  outbox_.deliver(state_, clock_.now());
  EXPECT_EQ(log_.take(), (Calls{"state 3 seq 2", "end 3"}));
  EXPECT_EQ(state_.updated_at, clock_.now());
  EXPECT_EQ(roster_.published()[0].position, 42);
}

TEST_F(HandOutboxTest, TheSameValuesReadAgainAreFreshAtMostOncePerInterval) {
  outbox_.deliver(state_, clock_.now());
  log_.take();
  const TimePoint first_read = state_.read_at;
  clock_.advance(kFresh - 1ms);
  state_.read_at = clock_.now();
  outbox_.deliver(state_, clock_.now());
  EXPECT_TRUE(log_.take().empty());
  clock_.advance(1ms);
  state_.read_at = clock_.now();
  outbox_.deliver(state_, clock_.now());
  EXPECT_EQ(log_.take(), (Calls{"fresh 3", "end 3"}));
  EXPECT_EQ(state_.sequence, 1u);  // the same values: no new sequence
  EXPECT_EQ(roster_.published()[0].read_at, first_read + kFresh);
  clock_.advance(1ms);
  state_.read_at = clock_.now();
  outbox_.deliver(state_, clock_.now());
  EXPECT_TRUE(log_.take().empty());
}

TEST_F(HandOutboxTest, StateThenEventsThenCompletionsThenTheBatchEnd) {
  std::vector<std::string>& calls = log_.calls;
  outbox_.add_event(event(EventKind::grasped));
  outbox_.add_completion(
      [&](const CommandResult& r) { calls.push_back(r ? "done ok" : "done fail"); },
      CommandSuccess{7, GraspOutcome::grasped}, clock_.now());
  outbox_.add_event(event(EventKind::arrived));
  outbox_.add_completion(
      [&](const CommandResult& r) { calls.push_back(r ? "done ok" : "done fail"); },
      fail(CommandError::timeout), clock_.now());
  outbox_.deliver(state_, clock_.now());
  EXPECT_EQ(log_.take(), (Calls{"state 3 seq 1", "event 3 grasped", "event 3 arrived", "done ok",
                                "done fail", "end 3"}));
}

TEST_F(HandOutboxTest, EventsAndCompletionsGoOutWithoutAStateAndWithoutABatchEnd) {
  outbox_.deliver(state_, clock_.now());
  log_.take();
  bool done = false;
  outbox_.add_event(event(EventKind::dropped));
  outbox_.add_completion([&](const CommandResult&) { done = true; }, CommandSuccess{},
                         clock_.now());
  outbox_.deliver(state_, clock_.now());
  EXPECT_EQ(log_.take(), (Calls{"event 3 dropped"}));
  EXPECT_TRUE(done);
  outbox_.deliver(state_, clock_.now());
  EXPECT_TRUE(log_.take().empty());  // delivered once
}

TEST_F(HandOutboxTest, IdZeroPublishesNoStateButItsCommandsComplete) {
  HandOutbox anonymous(log_, roster_, latency_, kFresh, true);
  HandState zero;
  zero.can_id = 0;
  bool done = false;
  anonymous.add_completion([&](const CommandResult&) { done = true; }, CommandSuccess{},
                           clock_.now());
  anonymous.publish_again();
  anonymous.deliver(zero, clock_.now());
  EXPECT_TRUE(done);
  EXPECT_TRUE(log_.take().empty());
  EXPECT_TRUE(roster_.published().empty());
  EXPECT_EQ(zero.sequence, 0u);
}

TEST_F(HandOutboxTest, PublishAgainRepublishesAnUnchangedState) {
  outbox_.deliver(state_, clock_.now());
  log_.take();
  outbox_.publish_again();
  outbox_.deliver(state_, clock_.now());
  EXPECT_EQ(log_.take(), (Calls{"state 3 seq 2", "end 3"}));
}

TEST_F(HandOutboxTest, ACompletionQueuedByACompletionWaitsForTheNextDelivery) {
  int second = 0;
  outbox_.add_completion(
      [&](const CommandResult&) {
        outbox_.add_completion([&](const CommandResult&) { ++second; }, CommandSuccess{},
                               clock_.now());
      },
      CommandSuccess{}, clock_.now());
  outbox_.deliver(state_, clock_.now());
  EXPECT_EQ(second, 0);
  outbox_.deliver(state_, clock_.now());
  EXPECT_EQ(second, 1);
}

TEST_F(HandOutboxTest, LatenciesAreMeasuredAtDelivery) {
  const TimePoint submitted = clock_.now();
  outbox_.add_completion({}, CommandSuccess{}, submitted);  // no callback: still counted
  clock_.advance(30ms);
  outbox_.deliver(state_, clock_.now());
  const auto to_reply = latency_.command_to_reply.snapshot();
  EXPECT_EQ(to_reply.total(), 1u);
  EXPECT_NEAR(to_reply.sum_seconds, 0.030, 1e-9);
  const auto age = latency_.sample_age.snapshot();
  EXPECT_EQ(age.total(), 1u);
  EXPECT_NEAR(age.sum_seconds, 0.030, 1e-9);  // read 30 ms before it went out
  // Nothing reported: no sample age.
  outbox_.deliver(state_, clock_.now());
  EXPECT_EQ(latency_.sample_age.snapshot().total(), 1u);
}

TEST_F(HandOutboxTest, AHandThatNeverAnsweredHasNoSampleAge) {
  state_.read_at = TimePoint{};
  outbox_.deliver(state_, clock_.now());
  EXPECT_EQ(log_.take(), (Calls{"state 3 seq 1", "end 3"}));
  EXPECT_EQ(latency_.sample_age.snapshot().total(), 0u);
}

}  // namespace
}  // namespace dh3::hand
