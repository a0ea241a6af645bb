// The line budget: requests spaced so that each with its reply fits the share
// of the line the scheduler offers, a few catching up after an idle moment.

#include <gtest/gtest.h>

#include <chrono>

#include "line_budget.hpp"

namespace dh3::hand {
namespace {

using namespace std::chrono_literals;

/// Requests `budget` allows at the clock's time, each one used.
int take_all(LineBudget& budget, const FakeClock& clock) {
  int taken = 0;
  while (budget.allows(clock.now()) && taken < 100) {
    budget.used(clock.now());
    ++taken;
  }
  return taken;
}

TEST(LineBudget, AnUnknownBitRateOrNoLoadLimitAllowsEverything) {
  FakeClock clock;
  for (LineBudget budget : {LineBudget(0, 0.8), LineBudget(1'000'000, 0.0)}) {
    EXPECT_EQ(budget.spacing(), Duration::zero());
    EXPECT_EQ(take_all(budget, clock), 100);
  }
}

TEST(LineBudget, ARequestAndItsReplyFitTheOfferedShare) {
  // Two frames of 135 bits at 1 Mbit/s take 270 us; at 80 % of the line,
  // 337.5 us (to the clock's nanosecond, which the double may round down).
  const Duration at_1m = LineBudget(1'000'000, 0.8).spacing();
  EXPECT_GE(at_1m, 337'499ns);
  EXPECT_LE(at_1m, 337'500ns);
  // At 500 kbit/s and half the line: 540 us / 0.5.
  const Duration at_500k = LineBudget(500'000, 0.5).spacing();
  EXPECT_GE(at_500k, 1'079'999ns);
  EXPECT_LE(at_500k, 1080us);
}

TEST(LineBudget, AfterAnIdleMomentAFewRequestsCatchUpAndNoMore) {
  FakeClock clock;
  LineBudget budget(1'000'000, 0.8);
  EXPECT_EQ(take_all(budget, clock), LineBudget::kLineBurst + 1);
  EXPECT_EQ(budget.next_at(), clock.now() + budget.spacing());
  clock.advance(budget.spacing() - 1ns);
  EXPECT_FALSE(budget.allows(clock.now()));
  clock.advance(1ns);
  EXPECT_TRUE(budget.allows(clock.now()));
}

TEST(LineBudget, ABusyLineGetsOneRequestPerSpacing) {
  FakeClock clock;
  LineBudget budget(250'000, 0.8);
  int taken = take_all(budget, clock);
  for (int step = 0; step < 40; ++step) {
    clock.advance(budget.spacing());
    taken += take_all(budget, clock);
  }
  EXPECT_EQ(taken, LineBudget::kLineBurst + 1 + 40);
}

TEST(LineBudget, ARequestPastTheBudgetIsStillCounted) {
  // A group's frames go back to back past the budget; the requests after them
  // wait their share.
  FakeClock clock;
  LineBudget budget(1'000'000, 0.8);
  for (int i = 0; i < 8; ++i) budget.used(clock.now());
  EXPECT_FALSE(budget.allows(clock.now()));
  EXPECT_EQ(budget.next_at(), clock.now() + 4 * budget.spacing());
}

TEST(LineBudget, IdleTimeIsNotSavedUpBeyondTheBurst) {
  FakeClock clock;
  LineBudget budget(1'000'000, 0.8);
  take_all(budget, clock);
  clock.advance(1s);
  EXPECT_EQ(take_all(budget, clock), LineBudget::kLineBurst + 1);
}

}  // namespace
}  // namespace dh3::hand
