// GroupCalls without DDS: what a group request may name, and how a group
// call filed in PendingCalls ends once: by its reply, its deadline, close()
// or the loss of the service instance it was sent to.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <variant>
#include <vector>

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

using Clock = PendingCalls::Clock;

/// A group call of `hands` hands of "cell" whose ends land in `ended`.
PendingCalls::Call group_call(GroupCommand command, std::uint16_t hands,
                              std::vector<GroupReply>* ended) {
  std::vector<HandAddress> addresses;
  for (std::uint16_t id = 1; id <= hands; ++id) addresses.push_back({"cell", "can0", id});
  auto call = GroupCalls::make_call(command, addresses, 50, Timeout(0), Timeout(500),
                                    [ended](GroupReply reply) { ended->push_back(reply); });
  EXPECT_TRUE(call);
  call->deadline = Clock::time_point{} + std::chrono::milliseconds(500);
  return std::move(call).value();
}

void run(std::vector<PendingCalls::Completion> completions) {
  for (auto& [done, reply] : completions) done(std::move(reply));
}

TEST(GroupCalls, AReplyIsTakenOnceAndACallerWhoGaveUpLosesNothingThatCame) {
  PendingCalls calls;
  std::vector<GroupReply> ended;
  calls.add(7, group_call(GroupCommand::move, 2, &ended));
  EXPECT_FALSE(calls.take(8));
  auto call = calls.take(7);
  ASSERT_TRUE(call && call->group);
  EXPECT_FALSE(calls.take(7));
  msg::GroupReply reply;
  reply.code(msg::OK);
  reply.message("done");
  call->group->done(GroupCalls::reply_of(reply));
  // The reply came before the deadline: the deadline ends nothing more.
  EXPECT_TRUE(calls.expire(Clock::time_point::max()).expired.empty());
  ASSERT_EQ(ended.size(), 1U);
  EXPECT_EQ(ended[0].message, "done");
  calls.add(9, group_call(GroupCommand::move, 2, &ended));
  auto given_up = calls.expire(Clock::time_point::max());
  ASSERT_EQ(given_up.expired.size(), 1U);
  const Reply expired = PendingCalls::expired_reply(given_up.expired[0], true, 0);
  EXPECT_EQ(expired.code, Code::no_service);
  EXPECT_EQ(expired.message, "service 'cell' with group commands not found in 500 ms");
  given_up.expired[0].sent_to = "aa";
  EXPECT_EQ(PendingCalls::expired_reply(given_up.expired[0], true, 0).message,
            "no group reply within 500 ms");
}

TEST(GroupCalls, CloseEndsEveryWaitingCallNotConnected) {
  PendingCalls calls;
  std::vector<GroupReply> ended;
  calls.add(1, group_call(GroupCommand::move, 2, &ended));
  calls.add(2, group_call(GroupCommand::move, 2, &ended));
  Reply closed;
  closed.code = Code::not_connected;
  run(calls.end_all(closed));
  ASSERT_EQ(ended.size(), 2U);
  EXPECT_EQ(ended[0].code, Code::not_connected);
  EXPECT_EQ(ended[1].code, Code::not_connected);
  EXPECT_FALSE(calls.take(1));
}

TEST(GroupCalls, LosingAServiceInstanceEndsOnlyTheCallsSentToItServiceLost) {
  PendingCalls calls;
  std::vector<GroupReply> to_old;
  std::vector<GroupReply> to_other;
  calls.add(1, group_call(GroupCommand::grasp, 3, &to_old));
  calls.find(1)->sent_to = "aa";
  calls.add(2, group_call(GroupCommand::move, 2, &to_other));
  calls.find(2)->sent_to = "bb";
  EXPECT_TRUE(calls.end_sent_to("", "nobody").empty());  // no instance known: nothing ends
  run(calls.end_sent_to("aa", "service 'cell' restarted"));
  ASSERT_EQ(to_old.size(), 1U);
  const GroupReply lost = to_old[0];
  EXPECT_EQ(lost.code, Code::service_lost);
  EXPECT_EQ(lost.message,
            "service 'cell' restarted while GROUP GRASP of 3 hand(s) was pending; it had been sent "
            "to that service, so it may or may not have reached the hand");
  EXPECT_TRUE(to_other.empty());
  EXPECT_TRUE(calls.take(2));
}

TEST(GroupCalls, WaitForTheirServicesGroupEndpointsWhereSingleCallsDoNot) {
  PendingCalls calls;
  std::vector<GroupReply> ended;
  calls.add(1, group_call(GroupCommand::move, 2, &ended));
  EXPECT_FALSE(calls.assign("cell", "aa", false));
  EXPECT_TRUE(calls.find(1)->sent_to.empty());
  EXPECT_TRUE(calls.assign("cell", "aa", true));
  const auto next = calls.next_to_write();
  ASSERT_TRUE(next);
  EXPECT_EQ(next->seq, 1U);
  EXPECT_TRUE(std::holds_alternative<msg::GroupRequest>(next->request));
}

}  // namespace
}  // namespace dh3::detail
