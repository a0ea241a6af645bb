// The minimum-interval check dh3-sim's hands apply to the frames they receive.

#include <gtest/gtest.h>

#include "dh3/sim/interval_watch.hpp"

namespace dh3::sim {
namespace {

using namespace std::chrono_literals;

const protocol::Message kRead = protocol::make_read(1, protocol::reg::kPosition);

TEST(IntervalWatch, CountsFramesToOneHandCloserThanTheMinimum) {
  IntervalWatch watch(20ms);
  EXPECT_FALSE(watch.note(1, 1000ms, kRead)) << "the first frame has no predecessor";
  EXPECT_TRUE(watch.note(1, 1005ms, kRead));
  EXPECT_FALSE(watch.note(1, 1025ms, kRead)) << "exactly the minimum is allowed";
  EXPECT_TRUE(watch.note(1, 1044ms, kRead));
  EXPECT_EQ(watch.violations(), 2u);
}

TEST(IntervalWatch, EachHandHasItsOwnInterval) {
  IntervalWatch watch(20ms);
  EXPECT_FALSE(watch.note(1, 1000ms, kRead));
  EXPECT_FALSE(watch.note(2, 1001ms, kRead));
  EXPECT_FALSE(watch.note(3, 1002ms, kRead));
  EXPECT_FALSE(watch.note(1, 1020ms, kRead));
  EXPECT_EQ(watch.violations(), 0u);
}

TEST(IntervalWatch, FramesNoHandTakesAsACommandAreNotCounted) {
  // Another node's frames on the line (kernel.service_faults floods it with
  // cangen): an unknown register, or a reserve byte other than 00.
  protocol::Message unknown_register = kRead;
  unknown_register.reg = protocol::Register{0x1F, 0x93};
  protocol::Message nonzero_reserve = kRead;
  nonzero_reserve.reserve = 0x26;
  IntervalWatch watch(20ms);
  EXPECT_FALSE(watch.note(1, 1000ms, kRead));
  EXPECT_FALSE(watch.note(1, 1005ms, unknown_register));
  EXPECT_FALSE(watch.note(1, 1010ms, nonzero_reserve));
  EXPECT_FALSE(watch.note(1, 1020ms, kRead)) << "measured from the last command";
  EXPECT_TRUE(watch.note(1, 1030ms, kRead));
  EXPECT_EQ(watch.violations(), 1u);
}

TEST(IntervalWatch, ATimeBeforeThePreviousOneRestartsTheMeasurement) {
  IntervalWatch watch(20ms);
  EXPECT_FALSE(watch.note(1, 1000ms, kRead));
  EXPECT_FALSE(watch.note(1, 900ms, kRead)) << "a clock stepped back is no violation";
  EXPECT_TRUE(watch.note(1, 910ms, kRead)) << "measured from the stepped time";
  EXPECT_EQ(watch.violations(), 1u);
}

TEST(IntervalWatch, OffCountsNothing) {
  IntervalWatch watch;
  EXPECT_FALSE(watch.enabled());
  EXPECT_FALSE(watch.note(1, 1000ms, kRead));
  EXPECT_FALSE(watch.note(1, 1000ms, kRead));
  EXPECT_EQ(watch.violations(), 0u);
}

}  // namespace
}  // namespace dh3::sim
