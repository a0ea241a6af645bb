// dh3-ros2's replies to clients whose reply reader has not matched yet: held,
// written once it matches, bounded in time and number.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "held_replies.hpp"

namespace dh3::ros2 {
namespace {

using std::chrono::seconds;
using Clock = HeldReplies::Clock;

struct Writes {
  std::vector<std::string> done;
  HeldReplies::Write of(std::string name) {
    return [this, name] { done.push_back(name); };
  }
};

void run(const std::vector<HeldReplies::Write>& due) {
  for (const auto& write : due) write();
}

TEST(HeldReplies, AReplyToAMatchedReaderIsWrittenAtOnce) {
  HeldReplies held(seconds(10), 8);
  const auto t0 = Clock::time_point{};
  EXPECT_TRUE(held.reader_matched("r1", true, t0).empty());
  Writes writes;
  EXPECT_TRUE(held.admit("r1", writes.of("a"), t0));
  EXPECT_EQ(held.held(), 0U);
}

TEST(HeldReplies, AReplyBeforeTheMatchIsWrittenWhenItsReaderMatchesInOrder) {
  HeldReplies held(seconds(10), 8);
  const auto t0 = Clock::time_point{};
  Writes writes;
  EXPECT_FALSE(held.admit("r1", writes.of("a"), t0));
  EXPECT_FALSE(held.admit("r2", writes.of("other"), t0));
  EXPECT_FALSE(held.admit("r1", writes.of("b"), t0));
  run(held.reader_matched("r1", true, t0 + seconds(1)));
  EXPECT_EQ(writes.done, (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(held.held(), 1U);  // r2's stays held
  EXPECT_TRUE(held.admit("r1", writes.of("c"), t0 + seconds(1)));
}

TEST(HeldReplies, AReaderThatLeftHoldsItsRepliesAgain) {
  HeldReplies held(seconds(10), 8);
  const auto t0 = Clock::time_point{};
  Writes writes;
  (void)held.reader_matched("r1", true, t0);
  (void)held.reader_matched("r1", false, t0);
  EXPECT_FALSE(held.admit("r1", writes.of("a"), t0));
}

TEST(HeldReplies, AReplyNeverMatchedIsDroppedAfterTheHoldLimit) {
  HeldReplies held(seconds(10), 8);
  const auto t0 = Clock::time_point{};
  Writes writes;
  EXPECT_FALSE(held.admit("r1", writes.of("a"), t0));
  EXPECT_TRUE(held.reader_matched("r9", true, t0 + seconds(10)).empty());
  EXPECT_EQ(held.held(), 0U);
  EXPECT_EQ(held.dropped(), 1U);
  run(held.reader_matched("r1", true, t0 + seconds(11)));
  EXPECT_TRUE(writes.done.empty());
}

TEST(HeldReplies, BeyondTheCapTheOldestIsDropped) {
  HeldReplies held(seconds(10), 2);
  const auto t0 = Clock::time_point{};
  Writes writes;
  EXPECT_FALSE(held.admit("r1", writes.of("a"), t0));
  EXPECT_FALSE(held.admit("r1", writes.of("b"), t0));
  EXPECT_FALSE(held.admit("r1", writes.of("c"), t0));
  EXPECT_EQ(held.held(), 2U);
  EXPECT_EQ(held.dropped(), 1U);
  run(held.reader_matched("r1", true, t0));
  EXPECT_EQ(writes.done, (std::vector<std::string>{"b", "c"}));
}

}  // namespace
}  // namespace dh3::ros2
