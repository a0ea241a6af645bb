// The hand's status a reply carries (CommandReply.status): cached before the
// call ends, each sample delivered to status callbacks once, and never rolled
// back by an older sample arriving later on the status topic.

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <vector>

#include "dh3/client.hpp"
#include "fake_service.hpp"
#include "support/test_domain.hpp"

namespace dh3 {
namespace {

using test::FakeService;
using test::reply_to;

constexpr std::chrono::seconds kDeadline{15};

std::string service_name() {
  return "fake" + std::to_string(::getpid());
}

ClientOptions options() {
  ClientOptions o;
  o.domain = test::test_domain();
  o.default_timeout = kDeadline;
  return o;
}

HandAddress hand_address(std::uint16_t id) {
  return {service_name(), "bus0", id};
}

/// Collects the status callbacks of one subscription.
class StatusLog {
 public:
  void add(const HandStatus& status) {
    {
      std::lock_guard lock(mutex_);
      seen_.push_back(status);
    }
    changed_.notify_all();
  }
  bool wait_for(const std::function<bool(const std::vector<HandStatus>&)>& pred) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, kDeadline, [&] { return pred(seen_); });
  }
  std::vector<HandStatus> seen() {
    std::lock_guard lock(mutex_);
    return seen_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<HandStatus> seen_;
};

TEST(ReplyStatusTest, TheStatusAReplyCarriesIsCachedBeforeTheCallEnds) {
  // The fake never publishes the changed status: only the reply has it.
  FakeService fake(test::test_domain(), service_name());
  fake.set_handler([&](const msg::CommandRequest& r) {
    auto reply = reply_to(r);
    reply.status(fake.make_status(1, true, r.value()));
    return std::vector{reply};
  });
  Client client(options());
  auto hand = client.wait_for_hand(hand_address(1).to_string(), kDeadline);
  ASSERT_TRUE(hand) << hand.message();
  ASSERT_TRUE(hand->move_to(60));
  const auto status = hand->status();
  ASSERT_TRUE(status);
  EXPECT_EQ(status->position, 60);
  EXPECT_EQ(client.status(hand_address(1))->position, 60);
}

TEST(ReplyStatusTest, AReplyWithoutAStatusLeavesTheCacheAlone) {
  FakeService fake(test::test_domain(), service_name());  // replies carry update_seq 0
  Client client(options());
  auto hand = client.wait_for_hand(hand_address(1).to_string(), kDeadline);
  ASSERT_TRUE(hand) << hand.message();
  const auto before = hand->status();
  ASSERT_TRUE(before);
  ASSERT_TRUE(hand->move_to(60));
  const auto after = hand->status();
  ASSERT_TRUE(after);
  EXPECT_EQ(after->position, before->position);
  EXPECT_EQ(after->update_seq, before->update_seq);
  EXPECT_TRUE(after->online);
}

TEST(ReplyStatusTest, ASampleTheReplyCarriedIsDeliveredToStatusCallbacksOnce) {
  // As dh3-service does: the reply carries the sample, the same sample
  // follows on the status topic.
  FakeService fake(test::test_domain(), service_name());
  fake.set_handler([&](const msg::CommandRequest& r) {
    auto reply = reply_to(r);
    auto status = fake.make_status(1, true, r.value());
    reply.status(status);
    fake.send_reply(reply);
    fake.publish(status);
    return std::vector<msg::CommandReply>{};
  });
  Client client(options());
  auto hand = client.wait_for_hand(hand_address(1).to_string(), kDeadline);
  ASSERT_TRUE(hand) << hand.message();
  StatusLog log;
  auto subscription =
      client.subscribe_status([&](const HandStatus& s) { log.add(s); }, hand_address(1));
  ASSERT_TRUE(log.wait_for([](const auto& seen) { return !seen.empty(); }));
  for (const std::int32_t position : {60, 61, 62}) ASSERT_TRUE(hand->move_to(position));
  // A newer sample after them: once it is seen, everything before it was.
  fake.publish_status(1, true, 99);
  ASSERT_TRUE(log.wait_for([](const auto& seen) { return seen.back().position == 99; }));
  const auto seen = log.seen();
  std::vector<std::int32_t> positions;
  for (std::size_t i = 1; i < seen.size(); ++i) {
    EXPECT_GT(seen[i].update_seq, seen[i - 1].update_seq) << "sample " << i;
    positions.push_back(seen[i].position);
  }
  EXPECT_EQ(positions, (std::vector<std::int32_t>{60, 61, 62, 99}));
}

TEST(ReplyStatusTest, AnOlderSampleAfterTheReplyDoesNotRollTheCacheBack) {
  FakeService fake(test::test_domain(), service_name());
  msg::HandStatus older;
  fake.set_handler([&](const msg::CommandRequest& r) {
    older = fake.make_status(1, true, 20);  // written before the reply's, arrives after it
    auto reply = reply_to(r);
    reply.status(fake.make_status(1, true, r.value()));
    return std::vector{reply};
  });
  Client client(options());
  auto hand = client.wait_for_hand(hand_address(1).to_string(), kDeadline);
  ASSERT_TRUE(hand) << hand.message();
  StatusLog log;
  auto subscription = client.subscribe_status([&](const HandStatus& s) { log.add(s); });
  ASSERT_TRUE(hand->move_to(60));
  ASSERT_EQ(fake.wait_requests(1, kDeadline).size(), 1U);  // `older` is set (the fake's lock)
  fake.publish(older);
  // One writer's samples arrive in the order written: once hand 2's marker
  // is here, hand 1's older sample was taken (and dropped).
  fake.publish_status(2, true, 77);
  ASSERT_TRUE(log.wait_for([](const auto& seen) {
    return !seen.empty() && seen.back().address.can_id == 2 && seen.back().position == 77;
  }));
  EXPECT_EQ(hand->status()->position, 60);
  for (const auto& s : log.seen()) EXPECT_NE(s.position, 20) << "the older sample was delivered";
}

TEST(ReplyStatusTest, ARestartedServicesStatusesReplaceTheOldOnesThoughTheirSequenceRestarts) {
  auto old_instance = std::make_unique<FakeService>(test::test_domain(), service_name());
  Client client(options());
  auto hand = client.wait_for_hand(hand_address(1).to_string(), kDeadline);
  ASSERT_TRUE(hand) << hand.message();
  for (int i = 0; i < 20; ++i) {
    old_instance->publish_status(1, true, 30 + i);
    ASSERT_TRUE(
        hand->wait_until([&](const HandStatus& s) { return s.position == 30 + i; }, kDeadline));
  }
  ASSERT_GT(hand->status()->update_seq, 20U);
  old_instance.reset();
  // Its first samples count from 1 again.
  FakeService new_instance(test::test_domain(), service_name());
  new_instance.publish_status(1, true, 45);
  EXPECT_TRUE(hand->wait_until(
      [](const HandStatus& s) { return s.online && s.position == 45 && s.update_seq < 20; },
      kDeadline));
}

}  // namespace
}  // namespace dh3
