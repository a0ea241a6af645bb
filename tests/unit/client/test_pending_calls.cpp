// PendingCalls without DDS or the clock: deadlines, the io thread's wake, the
// write queue, and how calls end when their service is lost or the client closes.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pending_calls.hpp"

namespace dh3::detail {
namespace {

using ::testing::HasSubstr;
using Clock = PendingCalls::Clock;
using std::chrono::milliseconds;

const Clock::time_point kT0{};  // the test's own clock, from 0

PendingCalls::Call call_for(const std::string& service, Clock::time_point deadline,
                            std::vector<Reply>* ended = nullptr) {
  PendingCalls::Call call;
  call.hand = HandAddress{service, "can0", 1};
  call.request.command(msg::MOVE);
  call.deadline = deadline;
  call.timeout = milliseconds(500);
  call.done = [ended](Reply reply) {
    if (ended != nullptr) ended->push_back(std::move(reply));
  };
  return call;
}

void run(std::vector<PendingCalls::Completion> completions) {
  for (auto& [done, reply] : completions) done(std::move(reply));
}

TEST(PendingCalls, OnlyADeadlineBeforeTheIoThreadsNextWakeWakesIt) {
  PendingCalls calls;
  EXPECT_TRUE(calls.add(calls.next_seq(), call_for("svc", kT0 + milliseconds(900))));
  const auto expiry = calls.expire(kT0);
  EXPECT_TRUE(expiry.expired.empty());
  EXPECT_EQ(expiry.next, kT0 + milliseconds(900));
  calls.set_next_wake(expiry.next);
  EXPECT_FALSE(calls.add(calls.next_seq(), call_for("svc", kT0 + milliseconds(950))));
  EXPECT_TRUE(calls.add(calls.next_seq(), call_for("svc", kT0 + milliseconds(100))));
}

TEST(PendingCalls, ExpireTakesTheCallsWhoseDeadlinePassedAndNamesTheNextOne) {
  PendingCalls calls;
  const auto first = calls.next_seq();
  calls.add(first, call_for("svc", kT0 + milliseconds(100)));
  calls.add(calls.next_seq(), call_for("svc", kT0 + milliseconds(300)));
  calls.add(calls.next_seq(), call_for("svc", kT0 + milliseconds(200)));
  const auto expiry = calls.expire(kT0 + milliseconds(100));  // at the deadline: expired
  ASSERT_EQ(expiry.expired.size(), 1U);
  EXPECT_EQ(expiry.next, kT0 + milliseconds(200));
  EXPECT_EQ(calls.find(first), nullptr);
  EXPECT_EQ(calls.expire(kT0 + milliseconds(300)).expired.size(), 2U);
  EXPECT_EQ(calls.expire(kT0 + milliseconds(300)).next, Clock::time_point::max());
}

TEST(PendingCalls, AnExpiredCallSaysWhetherItWasSentAndWhetherItsServiceWasFound) {
  auto call = call_for("svc", kT0);
  EXPECT_THAT(PendingCalls::expired_reply(call, false, 7).message,
              HasSubstr("no service 'svc' found on DDS domain 7"));
  const Reply found = PendingCalls::expired_reply(call, true, 7);
  EXPECT_EQ(found.code, Code::no_service);
  EXPECT_THAT(found.message, HasSubstr("did not become ready"));
  call.sent_to = "A";
  const Reply sent = PendingCalls::expired_reply(call, true, 7);
  EXPECT_EQ(sent.code, Code::no_reply);
  EXPECT_THAT(sent.message, HasSubstr("no reply from service 'svc'"));
}

TEST(PendingCalls, AssignQueuesTheUnsentCallsOfOneServiceInOrder) {
  PendingCalls calls;
  const auto a = calls.next_seq();
  const auto b = calls.next_seq();
  const auto c = calls.next_seq();
  calls.add(a, call_for("svc", kT0 + milliseconds(100)));
  calls.add(b, call_for("other", kT0 + milliseconds(100)));
  calls.add(c, call_for("svc", kT0 + milliseconds(100)));
  EXPECT_FALSE(calls.assign("none", "X"));
  EXPECT_TRUE(calls.assign("svc", "A"));
  EXPECT_FALSE(calls.assign("svc", "A"));  // already assigned
  EXPECT_EQ(calls.find(a)->sent_to, "A");
  EXPECT_TRUE(calls.find(b)->sent_to.empty());
  // A call that ended meanwhile is skipped: it must never be written.
  ASSERT_TRUE(calls.take(a));
  const auto next = calls.next_to_write();
  ASSERT_TRUE(next);
  EXPECT_EQ(next->seq, c);
  EXPECT_FALSE(calls.next_to_write());
  EXPECT_TRUE(calls.queue_empty());
}

TEST(PendingCalls, ALostIncarnationEndsOnlyTheCallsWrittenToIt) {
  PendingCalls calls;
  std::vector<Reply> ended;
  const auto sent = calls.next_seq();
  const auto waiting = calls.next_seq();
  calls.add(sent, call_for("svc", kT0 + milliseconds(100), &ended));
  calls.assign("svc", "A");
  calls.add(waiting, call_for("svc", kT0 + milliseconds(100), &ended));
  EXPECT_TRUE(calls.end_sent_to("", "why").empty());
  run(calls.end_sent_to("A", "service 'svc' restarted"));
  ASSERT_EQ(ended.size(), 1U);
  EXPECT_EQ(ended[0].code, Code::service_lost);
  EXPECT_THAT(ended[0].message, HasSubstr("service 'svc' restarted while MOVE"));
  EXPECT_EQ(calls.find(sent), nullptr);
  EXPECT_NE(calls.find(waiting), nullptr);  // waits for the next incarnation
}

TEST(PendingCalls, EndAllEndsEveryCallAndEmptiesTheQueue) {
  PendingCalls calls;
  std::vector<Reply> ended;
  calls.add(calls.next_seq(), call_for("svc", kT0 + milliseconds(100), &ended));
  calls.add(calls.next_seq(), call_for("other", kT0 + milliseconds(100), &ended));
  calls.assign("svc", "A");
  Reply closed;
  closed.code = Code::not_connected;
  run(calls.end_all(closed));
  ASSERT_EQ(ended.size(), 2U);
  EXPECT_EQ(ended[1].code, Code::not_connected);
  EXPECT_TRUE(calls.queue_empty());
  EXPECT_FALSE(calls.next_to_write());
}

TEST(PendingCalls, SequenceNumbersAreNeverReused) {
  PendingCalls calls;
  const auto first = calls.next_seq();
  EXPECT_GT(calls.next_seq(), first);
  calls.begin_write();
  EXPECT_EQ(calls.writes_in_flight(), 1);
  calls.end_write();
  EXPECT_EQ(calls.writes_in_flight(), 0);
}

}  // namespace
}  // namespace dh3::detail
