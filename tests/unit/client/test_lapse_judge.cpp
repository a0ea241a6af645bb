// LapseJudge on a fake clock (client/src/lapse_judge.hpp): a lapse that stands
// ends its calls with the service's loss if this process read all it
// received, only once it caught up if it was behind, and after the blind
// confirmation if its queues cannot be seen.

#include <gtest/gtest.h>

#include "dh3/contract/ownership.hpp"
#include "lapse_judge.hpp"

namespace dh3::detail {
namespace {

using namespace std::chrono_literals;
using State = ReceiveState;
using TimePoint = LapseJudge::TimePoint;

const TimePoint t0 = TimePoint{} + 1h;
const TimePoint believed = t0 + contract::kOwnerLapseConfirm;

TEST(LapseJudge, ACurrentProcessEndsTheCallsWhenTheLapseIsBelieved) {
  LapseJudge judge(t0);
  EXPECT_EQ(judge.next_look(), t0) << "the first look at once";
  judge.take(t0, State::current);
  EXPECT_FALSE(judge.calls_end(t0));
  EXPECT_EQ(judge.next_look(), believed) << "then when the lapse is believed";
  EXPECT_FALSE(judge.calls_end(believed)) << "not without a look then";
  judge.take(believed, State::current);
  EXPECT_TRUE(judge.calls_end(believed));
  EXPECT_EQ(judge.blind_end(), TimePoint::max());
}

TEST(LapseJudge, OneCurrentLookAfterTheConfirmationIsEnough) {
  // The io thread came late: its one look is after the confirmation.
  LapseJudge judge(t0);
  judge.take(believed + 40ms, State::current);
  EXPECT_TRUE(judge.calls_end(believed + 40ms));
}

TEST(LapseJudge, AProcessBehindWaitsUntilItWasCurrentForTheSpan) {
  LapseJudge judge(t0);
  judge.take(t0, State::behind);
  EXPECT_EQ(judge.next_look(), t0 + LapseJudge::kLookAgain);
  judge.take(believed, State::behind);
  EXPECT_FALSE(judge.calls_end(believed));
  const TimePoint caught_up = believed + 100ms;
  judge.take(caught_up, State::current);
  EXPECT_FALSE(judge.calls_end(caught_up)) << "just caught up: assertions may have been dropped";
  EXPECT_EQ(judge.next_look(), caught_up + LapseJudge::kLookAgain);
  judge.take(caught_up + LapseJudge::kCaughtUpSpan - 1ms, State::current);
  EXPECT_FALSE(judge.calls_end(caught_up + LapseJudge::kCaughtUpSpan - 1ms));
  judge.take(caught_up + LapseJudge::kCaughtUpSpan, State::current);
  EXPECT_TRUE(judge.calls_end(caught_up + LapseJudge::kCaughtUpSpan));
}

TEST(LapseJudge, ABehindLookInTheSpanStartsItAgain) {
  LapseJudge judge(t0);
  judge.take(t0, State::behind);
  judge.take(believed, State::current);
  judge.take(believed + 200ms, State::behind);
  judge.take(believed + 250ms, State::current);
  EXPECT_FALSE(judge.calls_end(believed + 250ms));
  judge.take(believed + 250ms + LapseJudge::kCaughtUpSpan, State::current);
  EXPECT_TRUE(judge.calls_end(believed + 250ms + LapseJudge::kCaughtUpSpan));
}

TEST(LapseJudge, AProcessThatStaysBehindNeverEndsTheCalls) {
  LapseJudge judge(t0);
  for (TimePoint at = t0; at < t0 + 1min; at += LapseJudge::kLookAgain) {
    judge.take(at, State::behind);
    ASSERT_FALSE(judge.calls_end(at));
  }
  EXPECT_EQ(judge.blind_end(), TimePoint::max()) << "its calls end at their deadline";
}

TEST(LapseJudge, QueuesThatCannotBeSeenEndTheCallsAfterTheBlindConfirmation) {
  LapseJudge judge(t0);
  judge.take(t0, State::unknown);
  EXPECT_EQ(judge.next_look(), TimePoint::max()) << "no more looks";
  EXPECT_EQ(judge.blind_end(), t0 + contract::kOwnerLapseCallConfirm);
  EXPECT_FALSE(judge.calls_end(t0 + contract::kOwnerLapseCallConfirm - 1ms));
  EXPECT_TRUE(judge.calls_end(t0 + contract::kOwnerLapseCallConfirm));
}

TEST(LapseJudge, AReportInTheFutureIsLookedAtThen) {
  // A claimant never seen asserting: its lapse is due a lease after its claim.
  const TimePoint due = t0 + contract::kOwnerLease;
  LapseJudge judge(due);
  EXPECT_EQ(judge.next_look(), due);
}

}  // namespace
}  // namespace dh3::detail
