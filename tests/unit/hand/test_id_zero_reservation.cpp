// Pacing across senders: a frame to CAN ID 0 reaches every hand, so it waits
// until no hand and no probe had a frame within the spacing, holds the others
// past its slot, and everyone waits the spacing after it.

#include <gtest/gtest.h>

#include <chrono>

#include "id_zero_reservation.hpp"

namespace dh3::hand {
namespace {

using namespace std::chrono_literals;

constexpr Duration kSpacing = 20ms;

class IdZeroReservationTest : public ::testing::Test {
 protected:
  FakeClock clock_;
  IdZeroReservation reservation_{kSpacing};
  const TimePoint start_ = clock_.now();
};

TEST_F(IdZeroReservationTest, NothingWaitingReservesNothing) {
  EXPECT_FALSE(reservation_.reserve(false, clock_.now()));
  EXPECT_FALSE(reservation_.slot());
  EXPECT_EQ(reservation_.probes_allowed_at(), TimePoint{});
}

TEST_F(IdZeroReservationTest, OnAQuietBusTheFrameMayGoAtOnce) {
  EXPECT_EQ(reservation_.reserve(true, clock_.now()), start_);
  EXPECT_TRUE(reservation_.may_send(clock_.now()));
}

TEST_F(IdZeroReservationTest, TheSlotWaitsTheSpacingAfterTheLastFrameToAnyHand) {
  reservation_.frame_sent(5, start_);
  clock_.advance(3ms);
  reservation_.frame_sent(7, clock_.now());
  clock_.advance(1ms);
  EXPECT_EQ(reservation_.reserve(true, clock_.now()), start_ + 3ms + kSpacing);
  EXPECT_FALSE(reservation_.may_send(clock_.now()));
}

TEST_F(IdZeroReservationTest, TheSlotIsNoEarlierThanIdZerosOwnPacing) {
  reservation_.frame_sent(5, start_);
  EXPECT_EQ(reservation_.reserve(true, start_ + 50ms), start_ + 50ms);
}

TEST_F(IdZeroReservationTest, AProbeCountsAsAFrameToAHand) {
  clock_.advance(2ms);
  reservation_.probe_sent(clock_.now());
  EXPECT_EQ(reservation_.others_clear_at(), clock_.now() + kSpacing);
  EXPECT_EQ(reservation_.reserve(true, clock_.now()), clock_.now() + kSpacing);
}

TEST_F(IdZeroReservationTest, TheSlotIsReservedOnceWhileTheFrameWaits) {
  reservation_.frame_sent(5, start_);
  const auto slot = reservation_.reserve(true, start_);
  ASSERT_EQ(slot, start_ + kSpacing);
  clock_.advance(5ms);
  EXPECT_FALSE(reservation_.reserve(true, clock_.now()));
  EXPECT_EQ(reservation_.slot(), slot);
  // Nothing waits any more (the command was cancelled): the slot is dropped.
  EXPECT_FALSE(reservation_.reserve(false, clock_.now()));
  EXPECT_FALSE(reservation_.slot());
}

TEST_F(IdZeroReservationTest, AFrameThatWentOutAfterTheReservationMovesTheSlot) {
  ASSERT_EQ(reservation_.reserve(true, start_), start_);
  // A delayed send to another hand left after the slot was taken.
  clock_.advance(1ms);
  reservation_.frame_sent(9, clock_.now());
  EXPECT_FALSE(reservation_.may_send(clock_.now()));
  EXPECT_FALSE(reservation_.slot());
  EXPECT_EQ(reservation_.reserve(true, clock_.now()), clock_.now() + kSpacing);
  clock_.advance(kSpacing);
  EXPECT_TRUE(reservation_.may_send(clock_.now()));
}

TEST_F(IdZeroReservationTest, ProbesWaitWhileTheFrameWaitsAndTheSpacingAfterIt) {
  reservation_.frame_sent(5, start_);
  const auto slot = reservation_.reserve(true, start_);
  ASSERT_TRUE(slot);
  EXPECT_EQ(reservation_.probes_allowed_at(), *slot + kSpacing);
  clock_.set(*slot + 2ms);  // it left a little late
  reservation_.frame_sent(0, clock_.now());
  EXPECT_FALSE(reservation_.slot());
  EXPECT_EQ(reservation_.probes_allowed_at(), clock_.now() + kSpacing);
}

TEST_F(IdZeroReservationTest, AFrameToIdZeroDoesNotDelayTheNextOne) {
  // Only frames to other hands and probes keep ID 0 waiting; its own spacing
  // is its driver's pacing.
  reservation_.frame_sent(0, start_);
  EXPECT_EQ(reservation_.others_clear_at(), TimePoint{} + kSpacing);
  EXPECT_EQ(reservation_.reserve(true, start_ + 1ms), start_ + 1ms);
}

}  // namespace
}  // namespace dh3::hand
