// ClientRate on a fake clock: a client may send its rate's worth at once,
// then one more each 1/rate seconds; one client over its rate costs another
// nothing; a client that left starts afresh; 0 is no limit.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "client_rate.hpp"

namespace dh3::dds {
namespace {

using ::testing::HasSubstr;
using namespace std::chrono_literals;

/// How many of `count` requests of `caller` are admitted now.
int admitted(ClientRate& rate, const std::string& caller, int count) {
  int ok = 0;
  for (int i = 0; i < count; ++i) ok += rate.admit(caller, caller + "@host").ok() ? 1 : 0;
  return ok;
}

TEST(ClientRate, ABurstOfTheRateThenOneEachIntervalBeyondItBusySayingWhy) {
  FakeClock clock;
  ClientRate rate(clock, 10);
  EXPECT_EQ(admitted(rate, "flood", 10), 10);
  const auto refused = rate.admit("flood", "dh3ctl@cell-pc");
  ASSERT_FALSE(refused.ok());
  EXPECT_THAT(refused.error(), HasSubstr("client 'dh3ctl@cell-pc' (participant flood)"));
  EXPECT_THAT(refused.error(), HasSubstr("more than 10 requests a second"));
  EXPECT_THAT(refused.error(), HasSubstr("client_rate_limit"));
  clock.advance(50ms);  // half an interval: nothing yet
  EXPECT_EQ(admitted(rate, "flood", 1), 0);
  clock.advance(50ms);  // one interval: one more
  EXPECT_EQ(admitted(rate, "flood", 5), 1);
  clock.advance(10s);  // a long pause refills the burst, never beyond it
  EXPECT_EQ(admitted(rate, "flood", 20), 10);
  EXPECT_EQ(rate.refused(), 1U + 1U + 4U + 10U);
}

TEST(ClientRate, OneClientOverItsRateCostsAnotherNothing) {
  FakeClock clock;
  ClientRate rate(clock, 5);
  EXPECT_EQ(admitted(rate, "flood", 1000), 5);
  EXPECT_EQ(admitted(rate, "other", 5), 5);
}

TEST(ClientRate, AClientThatLeftStartsAfreshAndZeroIsNoLimit) {
  FakeClock clock;
  ClientRate rate(clock, 3);
  EXPECT_EQ(admitted(rate, "a", 4), 3);
  rate.forget("a");
  EXPECT_EQ(admitted(rate, "a", 3), 3);

  ClientRate unlimited(clock, 0);
  EXPECT_EQ(admitted(unlimited, "a", 100000), 100000);
  EXPECT_EQ(unlimited.refused(), 0U);
}

}  // namespace
}  // namespace dh3::dds
