// MotionEnd (client/include/dh3/motion_end.hpp): which event ends the motion
// a command started, as dh3ctl's --wait and dh3-ros2's gripper action take it.

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "dh3/motion_end.hpp"

namespace dh3 {
namespace {

HandEvent event(EventKind kind, std::int32_t target) {
  HandEvent e;
  e.kind = kind;
  e.target = target;
  return e;
}

/// Whatever ended the motion by now; nothing if nothing did (no wait: the deadline has passed).
std::optional<HandEvent> ended(MotionEnd& end) {
  return end.wait(std::chrono::steady_clock::now() - std::chrono::seconds(1));
}

MotionEnd::Rule fingers_to(std::int32_t target) {
  MotionEnd::Rule rule;
  rule.target = target;
  return rule;
}

TEST(MotionEnd, AFingerMotionEndsWithItsOwnTargetOnly) {
  MotionEnd end(fingers_to(60));
  end.offer(event(EventKind::arrived, 20));  // the end of an earlier motion
  end.offer(event(EventKind::rotation_arrived, 60));
  end.offer(event(EventKind::fault, 60));
  EXPECT_FALSE(ended(end));
  end.offer(event(EventKind::grasped, 60));
  ASSERT_TRUE(ended(end));
  EXPECT_EQ(ended(end)->kind, EventKind::grasped);
}

TEST(MotionEnd, ARotationEndsWithARotationEvent) {
  MotionEnd::Rule rule;
  rule.rotation = true;
  rule.target = 30;
  MotionEnd end(rule);
  end.offer(event(EventKind::arrived, 30));
  EXPECT_FALSE(ended(end));
  end.offer(event(EventKind::rotation_blocked, 30));
  ASSERT_TRUE(ended(end));
  EXPECT_EQ(ended(end)->kind, EventKind::rotation_blocked);
}

TEST(MotionEnd, TheFirstEndIsKeptAndOfflineAlwaysEnds) {
  MotionEnd end(fingers_to(60));
  end.offer(event(EventKind::offline, 0));
  end.offer(event(EventKind::arrived, 60));
  ASSERT_TRUE(ended(end));
  EXPECT_EQ(ended(end)->kind, EventKind::offline);
}

TEST(MotionEnd, WithoutATargetAnyFingerEndAndWithFaultsADropOrFaultEnds) {
  MotionEnd::Rule rule;
  rule.faults_end = true;
  MotionEnd end(rule);
  end.offer(event(EventKind::rotation_arrived, 5));
  EXPECT_FALSE(ended(end));
  end.offer(event(EventKind::dropped, 5));
  ASSERT_TRUE(ended(end));
  EXPECT_EQ(ended(end)->kind, EventKind::dropped);

  MotionEnd any(MotionEnd::Rule{});
  any.offer(event(EventKind::fault, 5));
  EXPECT_FALSE(ended(any));
  any.offer(event(EventKind::missed, 5));
  EXPECT_TRUE(ended(any));
}

TEST(MotionEnd, AWaitReturnsTheEndOfferedFromAnotherThread) {
  MotionEnd end(fingers_to(60));
  std::thread dispatcher([&end] { end.offer(event(EventKind::arrived, 60)); });
  const auto got = end.wait(std::chrono::steady_clock::now() + std::chrono::seconds(60));
  dispatcher.join();
  ASSERT_TRUE(got);
  EXPECT_EQ(got->kind, EventKind::arrived);
}

TEST(MotionEnd, AWaitStopsWhenAskedTo) {
  MotionEnd end(fingers_to(60));
  int asked = 0;
  const auto got = end.wait(std::chrono::steady_clock::now() + std::chrono::hours(1),
                            [&asked] { return ++asked == 3; });
  EXPECT_FALSE(got);
  EXPECT_EQ(asked, 3);
}

}  // namespace
}  // namespace dh3
