// The axis watch, the same rules for the fingers and the rotation: a motion runs
// until a status ends it, where the axis stopped is read once after, unless a
// read during the motion found it at the target, and an arrival that may be
// from before the motion is decided by that read rather than believed.

#include <gtest/gtest.h>

#include "axis_watch.hpp"

namespace dh3::hand {
namespace {

template <class Motion>
class AxisWatchTest : public ::testing::Test {
 protected:
  /// A status as status_reading.hpp would have classified it.
  bool moving() { return watch_.take_status(true, false, false); }
  bool arrival() { return watch_.take_status(false, false, true); }
  bool stale_arrival() { return watch_.take_status(false, true, true); }
  bool stale_other() { return watch_.take_status(false, true, false); }

  void start_to(std::int32_t target) {
    Motion motion;
    motion.target = target;
    watch_.start(motion);
  }

  AxisWatch<Motion> watch_;
};

using Motions = ::testing::Types<FingerMotion, RotationMotion>;
TYPED_TEST_SUITE(AxisWatchTest, Motions);

TYPED_TEST(AxisWatchTest, AMotionRunsUntilAStatusEndsItThenWhereItStoppedIsReadOnce) {
  EXPECT_FALSE(this->watch_.motion());
  this->start_to(40);
  ASSERT_TRUE(this->watch_.motion());
  EXPECT_EQ(this->watch_.motion()->target, 40);
  EXPECT_TRUE(this->arrival());
  this->watch_.end(false);
  EXPECT_FALSE(this->watch_.motion());
  EXPECT_TRUE(this->watch_.read_due());
  EXPECT_TRUE(this->watch_.take_read_due());
  EXPECT_FALSE(this->watch_.take_read_due());
  EXPECT_FALSE(this->watch_.read_due());
}

TYPED_TEST(AxisWatchTest, AMotionThatStoppedWhereAReadFoundItNeedsNoFurtherRead) {
  this->start_to(40);
  EXPECT_FALSE(this->watch_.read_at_target(40));  // nothing read yet
  this->watch_.value_read();
  EXPECT_TRUE(this->watch_.read_at_target(40));
  EXPECT_FALSE(this->watch_.read_at_target(39));
  this->watch_.end(true);
  EXPECT_FALSE(this->watch_.read_due());
}

TYPED_TEST(AxisWatchTest, AReadBeforeTheMotionDoesNotPlaceIt) {
  this->start_to(40);
  this->watch_.value_read();
  this->start_to(60);
  EXPECT_FALSE(this->watch_.read_at_target(60));
  this->watch_.end(false);
  this->watch_.value_read();  // no motion: nothing to place
  this->start_to(60);
  EXPECT_FALSE(this->watch_.read_at_target(60));
}

TYPED_TEST(AxisWatchTest, AMovingStatusMarksTheMotionAsTakenByTheHand) {
  EXPECT_TRUE(this->moving());  // no motion: the hand's default, nothing marked
  this->start_to(40);
  EXPECT_FALSE(this->watch_.motion()->moving_seen);
  EXPECT_TRUE(this->moving());
  EXPECT_TRUE(this->watch_.motion()->moving_seen);
  this->start_to(50);
  EXPECT_FALSE(this->watch_.motion()->moving_seen);
}

TYPED_TEST(AxisWatchTest, AStaleArrivalIsDecidedByTheConfirmingReadSentAtOnce) {
  this->start_to(40);
  EXPECT_FALSE(this->stale_arrival());
  EXPECT_TRUE(this->watch_.motion());  // not ended by a reading that may be old
  EXPECT_TRUE(this->watch_.rechecking());
  EXPECT_TRUE(this->watch_.take_read_due());
  // The read is answered: the arrival is read again against it. Still far:
  // ignored, and no second read is asked for.
  EXPECT_FALSE(this->stale_arrival());
  EXPECT_FALSE(this->watch_.read_due());
  this->watch_.read_answered();
  EXPECT_FALSE(this->watch_.rechecking());
  EXPECT_TRUE(this->watch_.motion());
  // A later stale arrival asks again.
  EXPECT_FALSE(this->stale_arrival());
  EXPECT_TRUE(this->watch_.rechecking());
}

TYPED_TEST(AxisWatchTest, ARecheckedArrivalThatHoldsEndsTheMotionWithoutAnotherRead) {
  this->start_to(40);
  EXPECT_FALSE(this->stale_arrival());
  EXPECT_TRUE(this->watch_.take_read_due());
  EXPECT_TRUE(this->arrival());  // the read found the axis near the target
  this->watch_.end(false);
  this->watch_.read_answered();  // that read is where it stopped
  EXPECT_FALSE(this->watch_.motion());
  EXPECT_FALSE(this->watch_.read_due());
  EXPECT_FALSE(this->watch_.rechecking());
}

TYPED_TEST(AxisWatchTest, AStaleStatusThatIsNoArrivalIsIgnoredWithoutARead) {
  this->start_to(90);
  EXPECT_FALSE(this->stale_other());
  EXPECT_FALSE(this->watch_.read_due());
  EXPECT_FALSE(this->watch_.rechecking());
}

TYPED_TEST(AxisWatchTest, AConfirmingReadLostEndsTheRecheckTheStatusIsPolledAgain) {
  this->start_to(40);
  EXPECT_FALSE(this->stale_arrival());
  EXPECT_TRUE(this->watch_.take_read_due());
  this->watch_.read_lost();
  EXPECT_FALSE(this->watch_.rechecking());
  EXPECT_FALSE(this->watch_.read_due());
  EXPECT_TRUE(this->watch_.motion());
}

TYPED_TEST(AxisWatchTest, ARestartedInitializationForgetsTheMotionButNotTheDueRead) {
  this->start_to(40);
  this->watch_.end(false);
  this->start_to(50);
  this->watch_.forget_motion();
  EXPECT_FALSE(this->watch_.motion());
  EXPECT_TRUE(this->watch_.read_due());
}

TYPED_TEST(AxisWatchTest, ALostLinkClearsEverything) {
  this->start_to(40);
  EXPECT_FALSE(this->stale_arrival());
  this->watch_.clear();
  EXPECT_FALSE(this->watch_.motion());
  EXPECT_FALSE(this->watch_.read_due());
  EXPECT_FALSE(this->watch_.rechecking());
}

TYPED_TEST(AxisWatchTest, AnUndefinedStatusIsRememberedSoItIsReportedOnce) {
  EXPECT_EQ(this->watch_.last_undefined(), 0);
  this->watch_.undefined_reported(7);
  EXPECT_EQ(this->watch_.last_undefined(), 7);
  this->watch_.clear();  // a hand that keeps sending it after a reconnect is not reported again
  EXPECT_EQ(this->watch_.last_undefined(), 7);
}

}  // namespace
}  // namespace dh3::hand
