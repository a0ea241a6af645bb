// The frame slot: one frame in flight per hand, never two frames to it closer
// than the spacing, a reply matched on its register, a retryable frame that
// timed out re-sent before anything else and only so often.

#include <gtest/gtest.h>

#include <chrono>

#include "frame_slot.hpp"

namespace dh3::hand {
namespace {

using namespace std::chrono_literals;
namespace reg = protocol::reg;

constexpr Duration kSpacing = 20ms;
constexpr Duration kReplyTimeout = 150ms;
constexpr int kMaxRetries = 2;

protocol::Message read_position() {
  return protocol::make_read(3, reg::kPosition);
}

TEST(FrameSlot, AFrameInFlightKeepsTheNextOneBackUntilAnsweredAndSpaced) {
  FakeClock clock;
  FrameSlot slot(kSpacing, kMaxRetries, clock.now());
  EXPECT_TRUE(slot.clear_to_send(clock.now()));
  slot.send(read_position(), Purpose::poll, clock.now(), true, kReplyTimeout);
  ASSERT_NE(slot.in_flight(), nullptr);
  EXPECT_EQ(slot.in_flight()->deadline, clock.now() + kReplyTimeout);
  EXPECT_EQ(slot.paced_until(), clock.now() + kSpacing);

  clock.advance(5ms);
  EXPECT_FALSE(slot.clear_to_send(clock.now()));  // in flight
  ASSERT_TRUE(slot.take_answered(protocol::make_read(3, reg::kPosition)).has_value());
  EXPECT_EQ(slot.in_flight(), nullptr);
  EXPECT_FALSE(slot.clear_to_send(clock.now()));  // answered, but within the spacing

  clock.advance(kSpacing - 5ms - 1ns);
  EXPECT_FALSE(slot.clear_to_send(clock.now()));
  clock.advance(1ns);
  EXPECT_TRUE(slot.clear_to_send(clock.now()));
}

TEST(FrameSlot, TheReplyIsAwaitedFromWhenTheFrameLeftNotFromWhenItWasPutInFlight) {
  FakeClock clock;
  FrameSlot slot(kSpacing, kMaxRetries, clock.now());
  slot.send(protocol::make_write(3, reg::kPosition, 22), Purpose::job, clock.now(), true,
            kReplyTimeout);
  // The sender was held up for 120 ms before the frame reached the bus.
  clock.advance(120ms);
  slot.left_at(clock.now());
  clock.advance(kReplyTimeout - 1ms);
  EXPECT_FALSE(slot.expire(clock.now()).has_value()) << "timed out before its reply could come";
  ASSERT_TRUE(slot.take_answered(protocol::make_write(3, reg::kPosition, 22)).has_value());
  EXPECT_FALSE(slot.has_resend());

  // A frame that left at once keeps its deadline: left_at never shortens it.
  slot.send(read_position(), Purpose::poll, clock.now(), true, kReplyTimeout);
  slot.left_at(clock.now() - 10ms);
  clock.advance(kReplyTimeout);
  EXPECT_TRUE(slot.expire(clock.now()).has_value());
}

TEST(FrameSlot, AReplyMatchesOnItsRegisterOnly) {
  FakeClock clock;
  FrameSlot slot(kSpacing, kMaxRetries, clock.now());
  EXPECT_FALSE(slot.take_answered(read_position()).has_value());  // nothing in flight

  slot.send(protocol::make_write(3, reg::kPosition, 500), Purpose::job, clock.now(), true,
            kReplyTimeout);
  EXPECT_FALSE(slot.take_answered(protocol::make_read(3, reg::kRotation)).has_value());
  ASSERT_NE(slot.in_flight(), nullptr);
  // A read frame answers the write of the same register (the read/write byte
  // is not compared).
  const auto sent = slot.take_answered(read_position());
  ASSERT_TRUE(sent.has_value());
  EXPECT_EQ(sent->purpose, Purpose::job);
  EXPECT_EQ(sent->message.data, 500);
  EXPECT_EQ(sent->sent, clock.now());
}

TEST(FrameSlot, ATimedOutFrameIsResentFirstWithAFreshDeadline) {
  FakeClock clock;
  FrameSlot slot(kSpacing, kMaxRetries, clock.now());
  slot.send(read_position(), Purpose::refresh, clock.now(), true, kReplyTimeout);
  clock.advance(kReplyTimeout - 1ns);
  EXPECT_FALSE(slot.expire(clock.now()).has_value());
  clock.advance(1ns);
  const auto expired = slot.expire(clock.now());
  ASSERT_TRUE(expired.has_value());
  EXPECT_TRUE(expired->resent);
  EXPECT_EQ(expired->lost.attempts, 1);
  EXPECT_EQ(slot.in_flight(), nullptr);
  EXPECT_TRUE(slot.has_resend());

  const auto again = slot.send_again(clock.now());
  ASSERT_TRUE(again.has_value());
  EXPECT_EQ(again->reg, reg::kPosition);
  EXPECT_FALSE(slot.has_resend());
  ASSERT_NE(slot.in_flight(), nullptr);
  EXPECT_EQ(slot.in_flight()->attempts, 2);
  EXPECT_EQ(slot.in_flight()->purpose, Purpose::refresh);
  EXPECT_EQ(slot.in_flight()->deadline, clock.now() + kReplyTimeout);
  EXPECT_EQ(slot.paced_until(), clock.now() + kSpacing);
}

TEST(FrameSlot, AResendWaitsForThePacing) {
  FakeClock clock;
  FrameSlot slot(kSpacing, kMaxRetries, clock.now());
  slot.send(read_position(), Purpose::poll, clock.now(), true, 5ms);
  clock.advance(5ms);
  ASSERT_TRUE(slot.expire(clock.now()).has_value());
  EXPECT_FALSE(slot.send_again(clock.now()).has_value());  // 5 ms after the frame
  EXPECT_TRUE(slot.has_resend());
  clock.advance(kSpacing - 5ms);
  EXPECT_TRUE(slot.send_again(clock.now()).has_value());
}

TEST(FrameSlot, AFrameIsTriedOnePlusMaxRetriesTimes) {
  FakeClock clock;
  FrameSlot slot(kSpacing, kMaxRetries, clock.now());
  slot.send(read_position(), Purpose::job, clock.now(), true, kReplyTimeout);
  int tries = 1;
  for (;;) {
    clock.advance(kReplyTimeout);
    const auto expired = slot.expire(clock.now());
    ASSERT_TRUE(expired.has_value());
    EXPECT_EQ(expired->lost.attempts, tries);
    if (!expired->resent) break;
    ASSERT_TRUE(slot.send_again(clock.now()).has_value());
    ++tries;
    ASSERT_LE(tries, 10);
  }
  EXPECT_EQ(tries, 1 + kMaxRetries);
  EXPECT_FALSE(slot.has_resend());
  EXPECT_EQ(slot.in_flight(), nullptr);
}

TEST(FrameSlot, AFrameThatMayNotBeRepeatedIsNeverResent) {
  // A CAN ID or baud-rate write replies once stored: a re-send would store twice.
  FakeClock clock;
  FrameSlot slot(kSpacing, kMaxRetries, clock.now());
  slot.send(protocol::make_write(3, reg::kCanId, 4), Purpose::job, clock.now(), false, 3s);
  clock.advance(3s);
  const auto expired = slot.expire(clock.now());
  ASSERT_TRUE(expired.has_value());
  EXPECT_FALSE(expired->resent);
  EXPECT_FALSE(slot.has_resend());
}

TEST(FrameSlot, AnUnsentFrameIsOfferedAgainAtOnce) {
  // The bus would block: the frame did not reach the hand, so the pacing is
  // as it was before it and the frame goes first.
  FakeClock clock;
  FrameSlot slot(kSpacing, kMaxRetries, clock.now());
  clock.advance(1s);
  slot.send(read_position(), Purpose::poll, clock.now(), true, kReplyTimeout);
  slot.unsend();
  EXPECT_EQ(slot.in_flight(), nullptr);
  EXPECT_TRUE(slot.has_resend());
  EXPECT_EQ(slot.paced_until(), clock.now());
  ASSERT_TRUE(slot.send_again(clock.now()).has_value());
  EXPECT_EQ(slot.in_flight()->attempts, 1);

  EXPECT_TRUE(slot.take_answered(read_position()).has_value());
  slot.unsend();  // nothing in flight: nothing changes
  EXPECT_FALSE(slot.has_resend());
  EXPECT_EQ(slot.paced_until(), clock.now() + kSpacing);
}

TEST(FrameSlot, AHoldOnlyEverLengthensThePacing) {
  FakeClock clock;
  FrameSlot slot(kSpacing, kMaxRetries, clock.now());
  slot.send(read_position(), Purpose::poll, clock.now(), true, kReplyTimeout);
  EXPECT_TRUE(slot.take_answered(read_position()).has_value());
  slot.hold_sends_until(clock.now() + 5ms);
  EXPECT_EQ(slot.paced_until(), clock.now() + kSpacing);
  slot.hold_sends_until(clock.now() + 50ms);
  EXPECT_EQ(slot.paced_until(), clock.now() + 50ms);
  clock.advance(50ms - 1ns);
  EXPECT_FALSE(slot.clear_to_send(clock.now()));
  clock.advance(1ns);
  EXPECT_TRUE(slot.clear_to_send(clock.now()));
}

TEST(FrameSlot, ClearingForgetsTheFramesButKeepsThePacing) {
  // A lost link: nothing is awaited any more, yet a hand that answers again
  // still gets its interval after the last frame sent to it.
  FakeClock clock;
  FrameSlot slot(kSpacing, kMaxRetries, clock.now());
  const TimePoint start = clock.now();
  slot.send(read_position(), Purpose::poll, start, true, 5ms);
  FrameSlot resending = slot;  // the same frame, to be re-sent instead of in flight
  clock.advance(5ms);
  ASSERT_TRUE(resending.expire(clock.now()).has_value());
  ASSERT_TRUE(resending.has_resend());
  for (FrameSlot* cleared : {&slot, &resending}) {
    cleared->clear();
    EXPECT_EQ(cleared->in_flight(), nullptr);
    EXPECT_FALSE(cleared->has_resend());
    EXPECT_EQ(cleared->paced_until(), start + kSpacing);
    EXPECT_FALSE(cleared->clear_to_send(clock.now()));
    EXPECT_FALSE(cleared->send_again(start + kSpacing).has_value());
  }
}

}  // namespace
}  // namespace dh3::hand
