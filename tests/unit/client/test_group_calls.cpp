// GroupCalls without DDS: what a group request may name, and how a reply, a
// caller giving up and close() settle a call once.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <future>

#include "group_calls.hpp"

namespace dh3::detail {
namespace {

using ::testing::HasSubstr;

TEST(GroupCalls, ARequestNamesHandsOfOneServiceEachWithinTheContractsLimits) {
  const std::vector<HandAddress> hands{{"svc", "can0", 1}, {"svc", "can1", 2}};
  auto request = GroupCalls::make_request(GroupCommand::move, hands, 50, Timeout(2000));
  ASSERT_TRUE(request);
  EXPECT_EQ(request->service(), "svc");
  EXPECT_EQ(request->command(), msg::MOVE);
  EXPECT_EQ(request->timeout_ms(), 2000U);
  EXPECT_EQ(request->hands().size(), 2U);

  EXPECT_EQ(GroupCalls::make_request(GroupCommand::move, {}, 50, Timeout(0)).error().code,
            Code::invalid_argument);
  const auto mixed = GroupCalls::make_request(
      GroupCommand::move, {{"svc", "can0", 1}, {"other", "can0", 1}}, 50, Timeout(0));
  ASSERT_FALSE(mixed);
  EXPECT_THAT(mixed.error().message, HasSubstr("one service"));
  const auto too_far = GroupCalls::make_request(GroupCommand::move, hands, 150, Timeout(0));
  ASSERT_FALSE(too_far);
  EXPECT_EQ(too_far.error().code, Code::invalid_argument);
  EXPECT_THAT(too_far.error().message, HasSubstr("svc/can0/1"));
}

TEST(GroupCalls, ATimeoutOverTheContractsMaximumIsRefusedBeforeAnythingIsSent) {
  const std::vector<HandAddress> hands{{"svc", "can0", 1}};
  const auto at_most = GroupCalls::make_request(GroupCommand::initialize, hands, 0,
                                                std::chrono::milliseconds(60000));
  EXPECT_TRUE(at_most);
  const auto over = GroupCalls::make_request(GroupCommand::initialize, hands, 0,
                                             std::chrono::milliseconds(60001));
  ASSERT_FALSE(over);
  EXPECT_EQ(over.error().code, Code::invalid_argument);
  EXPECT_EQ(over.error().message, "a group's timeout is at most 60000 ms, not 60001 ms");
}

TEST(GroupCalls, AReplyIsTakenOnceAndACallerWhoGaveUpLosesNothingThatCame) {
  GroupCalls calls;
  auto future = calls.add(7, "aa", "GROUP MOVE of 2 hand(s)");
  EXPECT_EQ(calls.take(8), nullptr);
  auto promise = calls.take(7);
  ASSERT_NE(promise, nullptr);
  EXPECT_EQ(calls.take(7), nullptr);
  msg::GroupReply reply;
  reply.code(msg::OK);
  reply.message("done");
  promise->set_value(GroupCalls::reply_of(reply));
  // The reply came before the caller gave up: forget() says so, the future has it.
  EXPECT_FALSE(calls.forget(7));
  EXPECT_EQ(future.get().message, "done");
  auto given_up = calls.add(9, "aa", "GROUP MOVE of 2 hand(s)");
  EXPECT_TRUE(calls.forget(9));
}

TEST(GroupCalls, CloseEndsEveryWaitingCallNotConnected) {
  GroupCalls calls;
  auto first = calls.add(1, "aa", "GROUP MOVE of 2 hand(s)");
  auto second = calls.add(2, "aa", "GROUP MOVE of 2 hand(s)");
  calls.close();
  EXPECT_EQ(first.get().code, Code::not_connected);
  EXPECT_EQ(second.get().code, Code::not_connected);
  EXPECT_EQ(calls.take(1), nullptr);
}

TEST(GroupCalls, LosingAServiceInstanceEndsOnlyTheCallsSentToItServiceLost) {
  GroupCalls calls;
  auto to_old = calls.add(1, "aa", "GROUP GRASP of 3 hand(s)");
  auto to_other = calls.add(2, "bb", "GROUP MOVE of 2 hand(s)");
  calls.lose("", "nobody");  // no instance known: nothing ends
  calls.lose("aa", "service 'cell' restarted");
  ASSERT_EQ(to_old.wait_for(std::chrono::seconds(0)), std::future_status::ready);
  const GroupReply lost = to_old.get();
  EXPECT_EQ(lost.code, Code::service_lost);
  EXPECT_EQ(lost.message,
            "service 'cell' restarted while GROUP GRASP of 3 hand(s) was pending; it may or may "
            "not have run");
  EXPECT_EQ(to_other.wait_for(std::chrono::seconds(0)), std::future_status::timeout);
  EXPECT_NE(calls.take(2), nullptr);
}

}  // namespace
}  // namespace dh3::detail
