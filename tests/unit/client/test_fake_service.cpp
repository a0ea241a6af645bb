// libdh3client against a fake service on the wire (fake_service.hpp): late
// joiners, correlation (other clients' replies never resolve our calls),
// calls made before the service appears, the service leaving and coming back,
// events and safe unsubscription, threads, closing the client, completion
// callbacks.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <future>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "dh3/client.hpp"
#include "dh3/registers.hpp"
#include "fake_service.hpp"
#include "heard.hpp"
#include "support/test_domain.hpp"

namespace dh3 {
namespace {

using test::FakeService;
using test::Heard;
using test::reply_to;
using ::testing::HasSubstr;

constexpr std::chrono::seconds kDeadline{15};

using test::test_domain;
std::string service_name() {
  return "fake" + std::to_string(::getpid());
}

ClientOptions options() {
  ClientOptions o;
  o.domain = test_domain();
  o.default_timeout = kDeadline;
  return o;
}

HandAddress hand_address(std::uint16_t id) {
  return {service_name(), "bus0", id};
}

bool is_ready(std::future<Reply>& future) {
  return future.wait_for(kDeadline) == std::future_status::ready;
}

/// Collects events from a callback; the test waits on what arrived.
class EventLog {
 public:
  void add(const HandEvent& event) {
    {
      std::lock_guard lock(mutex_);
      events_.push_back(event);
    }
    changed_.notify_all();
  }
  bool wait_for(const std::function<bool(const std::vector<HandEvent>&)>& pred) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, kDeadline, [&] { return pred(events_); });
  }
  std::vector<HandEvent> events() {
    std::lock_guard lock(mutex_);
    return events_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<HandEvent> events_;
};

TEST(ClientTest, LateJoinerGetsServiceInfoAndEveryStatusAtOnce) {
  FakeService fake(test_domain(), service_name());
  ASSERT_TRUE(fake.ok());
  Client client(options());
  ASSERT_TRUE(client.connected()) << client.error();
  const auto info = client.wait_for_service(service_name(), kDeadline);
  ASSERT_TRUE(info) << info.message();
  EXPECT_TRUE(info->ready);
  EXPECT_EQ(info->version, "fake");
  ASSERT_EQ(info->buses.size(), 1U);
  EXPECT_EQ(info->buses[0].hands.size(), 2U);
  ASSERT_TRUE(client.wait_for_statuses(kDeadline));
  const auto hands = client.hands();
  ASSERT_EQ(hands.size(), 2U);
  EXPECT_EQ(hands[0].address, hand_address(1));
  EXPECT_TRUE(hands[0].online);
  EXPECT_EQ(hands[1].name, "hand2");
  const auto by_name = client.find_hand("hand2");
  ASSERT_TRUE(by_name) << by_name.message();
  EXPECT_EQ(by_name->address(), hand_address(2));
}

TEST(ClientTest, CallsGetTheServicesReplyWithItsCodeAndValue) {
  FakeService fake(test_domain(), service_name());
  fake.set_handler([](const msg::CommandRequest& r) {
    auto reply = reply_to(r);
    if (r.command() == msg::GRASP) {
      reply.grasp(msg::MISSED);
      reply.value(3);
    } else if (r.command() == msg::STOP) {
      reply.code(msg::NOT_INITIALIZED);
      reply.message("hand 1 on bus 'bus0' is not initialized");
    } else if (r.command() == msg::READ_REGISTER) {
      reply.value(r.register_code() == reg::firmware_version ? 0x04010200 : -1);
    }
    return std::vector{reply};
  });
  Client client(options());
  auto hand = client.wait_for_hand(hand_address(1).to_string(), kDeadline);
  ASSERT_TRUE(hand) << hand.message();

  const Reply move = hand->move_to(60);
  EXPECT_TRUE(move) << move.message;
  EXPECT_EQ(move.value, 60);
  const Reply grasp = hand->grasp(40);
  EXPECT_TRUE(grasp);
  EXPECT_EQ(grasp.grasp, GraspOutcome::missed);
  EXPECT_EQ(grasp.value, 3);
  const Reply stop = hand->stop();
  EXPECT_EQ(stop.code, Code::not_initialized);
  EXPECT_EQ(stop.message, "hand 1 on bus 'bus0' is not initialized");
  EXPECT_EQ(hand->read(reg::firmware_version).value, 0x04010200);

  // The service saw this client's id and a distinct sequence number per call.
  const auto requests = fake.wait_requests(4, kDeadline);
  ASSERT_EQ(requests.size(), 4U);
  for (const auto& r : requests) EXPECT_EQ(r.client_id(), client.client_id());
  EXPECT_NE(requests[0].request_seq(), requests[1].request_seq());
}

TEST(ClientTest, RepliesToOtherClientsNeverResolveOurCalls) {
  FakeService fake(test_domain(), service_name());
  // Before our own reply: the same sequence number under another client's id,
  // and the other client's id with our command. Only the last is ours.
  fake.set_handler([](const msg::CommandRequest& r) {
    auto foreign = reply_to(r);
    foreign.client_id("0102030405060708090a0b0c");
    foreign.value(111);
    auto foreign_failure = reply_to(r, msg::FAILED);
    foreign_failure.client_id("somebody-else");
    auto own = reply_to(r);
    own.value(222);
    return std::vector{foreign, foreign_failure, own};
  });
  Client client(options());
  auto hand = client.wait_for_hand(hand_address(1).to_string(), kDeadline);
  ASSERT_TRUE(hand) << hand.message();
  for (int i = 0; i < 5; ++i) {
    const Reply reply = hand->move_to(50);
    EXPECT_TRUE(reply) << reply.message;
    EXPECT_EQ(reply.value, 222);
  }
}

TEST(ClientTest, OnlyForeignRepliesMeansNoReply) {
  FakeService fake(test_domain(), service_name());
  fake.set_handler([](const msg::CommandRequest& r) {
    auto foreign = reply_to(r);
    foreign.client_id("not-" + r.client_id());
    return std::vector{foreign};
  });
  Client client(options());
  auto hand = client.wait_for_hand(hand_address(1).to_string(), kDeadline);
  ASSERT_TRUE(hand) << hand.message();
  // Long enough for the fake's reader to acknowledge (heartbeats every 100 ms).
  const Reply reply = hand->move_to(50, std::chrono::seconds(3));
  EXPECT_EQ(reply.code, Code::no_reply);
  EXPECT_THAT(reply.message, HasSubstr("no reply from service '" + service_name() + "'"));
  EXPECT_THAT(reply.message, HasSubstr("MOVE for " + hand_address(1).to_string()));
  // The fake took the request: the caller learns the move may have run.
  EXPECT_THAT(reply.message, HasSubstr("the service acknowledged the request"));
}

TEST(ClientTest, TwoClientsOnOneServiceEachGetTheirOwnReplies) {
  FakeService fake(test_domain(), service_name());
  Client a(options());
  Client b(options());
  auto hand_a = a.wait_for_hand(hand_address(1).to_string(), kDeadline);
  auto hand_b = b.wait_for_hand(hand_address(1).to_string(), kDeadline);
  ASSERT_TRUE(hand_a && hand_b);
  ASSERT_NE(a.client_id(), b.client_id());
  // Both number their requests from 1: their sequence numbers collide, and
  // each sees the other's replies on the shared reply topic.
  for (int i = 0; i < 20; ++i) {
    auto from_a = hand_a->move_to_async(10);
    auto from_b = hand_b->move_to_async(90);
    ASSERT_TRUE(is_ready(from_a) && is_ready(from_b));
    const Reply ra = from_a.get();
    const Reply rb = from_b.get();
    EXPECT_TRUE(ra && rb) << ra.message << " / " << rb.message;
    EXPECT_EQ(ra.value, 10);
    EXPECT_EQ(rb.value, 90);
  }
}

TEST(ClientTest, ACallMadeBeforeTheServiceAppearsGoesOutOnceItIsReady) {
  Client client(options());
  Hand hand = client.hand(hand_address(1));
  auto pending = hand.move_to_async(30);
  EXPECT_FALSE(hand.status());
  FakeService fake(test_domain(), service_name());
  ASSERT_TRUE(is_ready(pending));
  const Reply reply = pending.get();
  EXPECT_TRUE(reply) << reply.message;
  EXPECT_EQ(reply.value, 30);
}

TEST(ClientTest, NoServiceBeforeTheDeadlineSaysSo) {
  Client client(options());
  const Reply reply = client.hand(hand_address(1)).initialize(std::chrono::milliseconds(300));
  EXPECT_EQ(reply.code, Code::no_service);
  EXPECT_THAT(reply.message, HasSubstr("no service '" + service_name() + "'"));
  EXPECT_THAT(reply.message, HasSubstr("domain " + std::to_string(test_domain())));

  const auto service = client.wait_for_service({}, std::chrono::milliseconds(300));
  EXPECT_EQ(service.code(), Code::no_service);
  const auto hand = client.wait_for_hand("hand1", std::chrono::milliseconds(300));
  EXPECT_EQ(hand.code(), Code::no_service);
}

TEST(ClientTest, UnknownAndAmbiguousHandsAreReportedAsSuch) {
  FakeService fake(test_domain(), service_name());
  FakeService other(test_domain(), service_name() + "b");
  Client client(options());
  ASSERT_TRUE(client.wait_for_hand(hand_address(1).to_string(), kDeadline));
  ASSERT_TRUE(client.wait_for_hand(service_name() + "b/bus0/1", kDeadline));

  const auto unknown =
      client.wait_for_hand(hand_address(9).to_string(), std::chrono::milliseconds(300));
  EXPECT_EQ(unknown.code(), Code::unknown_hand);
  EXPECT_THAT(unknown.message(), HasSubstr("has no hand bus0/9"));
  const auto ambiguous = client.wait_for_hand("1", kDeadline);
  EXPECT_EQ(ambiguous.code(), Code::invalid_argument);
  EXPECT_THAT(ambiguous.message(), HasSubstr("ambiguous"));
  const auto qualified = client.wait_for_hand(service_name() + "b/hand2", kDeadline);
  ASSERT_TRUE(qualified) << qualified.message();
  EXPECT_EQ(qualified->address(), (HandAddress{service_name() + "b", "bus0", 2}));
}

TEST(ClientTest, ServiceLeavingEndsPendingCallsAndTakesItsHandsOffline) {
  auto fake = std::make_unique<FakeService>(test_domain(), service_name());
  fake->set_handler([](const msg::CommandRequest&) { return std::vector<msg::CommandReply>{}; });
  Client client(options());
  auto hand = client.wait_for_hand(hand_address(1).to_string(), kDeadline);
  ASSERT_TRUE(hand) << hand.message();
  EventLog log;
  auto subscription = hand->subscribe([&log](const HandEvent& e) { log.add(e); });

  auto pending = hand->initialize_async();
  ASSERT_EQ(fake->wait_requests(1, kDeadline).size(), 1U) << "the request never arrived";
  fake.reset();  // the service's participant leaves the domain

  ASSERT_TRUE(is_ready(pending));
  const Reply reply = pending.get();
  EXPECT_EQ(reply.code, Code::service_lost);
  EXPECT_THAT(reply.message, HasSubstr("left the domain while INITIALIZE"));
  const auto offline = hand->wait_until([](const HandStatus& s) { return !s.online; });
  ASSERT_TRUE(offline);
  EXPECT_TRUE(offline->service_lost);
  EXPECT_TRUE(log.wait_for([](const auto& events) {
    return !events.empty() && events.back().kind == EventKind::offline && events.back().from_client;
  }));
  EXPECT_GT(log.events().back().timestamp_ns, 0U) << "the client's OFFLINE event says when";
  EXPECT_FALSE(client.service(service_name())->ready);

  // It comes back: the same Hand works again.
  FakeService back(test_domain(), service_name());
  EXPECT_TRUE(hand->wait_until([](const HandStatus& s) { return s.online; }));
  const Reply again = hand->initialize();
  EXPECT_TRUE(again) << again.message;
}

TEST(ClientTest, ARestartEndsTheCallsPendingOnTheOldInstance) {
  // The old instance never says goodbye (as if killed); the new one's
  // arrival under the same name is what tells the client.
  FakeService old_instance(test_domain(), service_name());
  old_instance.set_handler(
      [](const msg::CommandRequest&) { return std::vector<msg::CommandReply>{}; });
  Client client(options());
  auto hand = client.wait_for_hand(hand_address(1).to_string(), kDeadline);
  ASSERT_TRUE(hand) << hand.message();
  auto pending = hand->grasp_async(40);
  ASSERT_EQ(old_instance.wait_requests(1, kDeadline).size(), 1U);

  FakeService new_instance(test_domain(), service_name());
  ASSERT_TRUE(is_ready(pending));
  const Reply reply = pending.get();
  EXPECT_EQ(reply.code, Code::service_lost);
  EXPECT_THAT(reply.message, HasSubstr("restarted"));
  const Reply move = hand->move_to(70);
  EXPECT_TRUE(move) << move.message;
  EXPECT_EQ(move.value, 70);
}

TEST(ClientTest, HandSubscriptionGetsOnlyItsHandsEvents) {
  FakeService fake(test_domain(), service_name());
  Client client(options());
  ASSERT_TRUE(client.wait_for_service(service_name(), kDeadline));
  EventLog log;
  auto subscription =
      client.hand(hand_address(1)).subscribe([&log](const HandEvent& e) { log.add(e); });
  fake.publish_event(2, msg::EVENT_ARRIVED);
  fake.publish_event(1, msg::EVENT_GRASPED, 40);
  // Events of one writer arrive in order: hand 2's came first if it came at all.
  ASSERT_TRUE(log.wait_for([](const auto& events) { return !events.empty(); }));
  const auto events = log.events();
  EXPECT_EQ(events.front().hand, hand_address(1));
  EXPECT_EQ(events.front().kind, EventKind::grasped);
  EXPECT_EQ(events.front().value, 40);
  EXPECT_FALSE(events.front().from_client);
}

TEST(ClientTest, UnsubscribeIsSafeWhileEventsArrive) {
  FakeService fake(test_domain(), service_name());
  Client client(options());
  ASSERT_TRUE(client.wait_for_service(service_name(), kDeadline));
  std::atomic<bool> unsubscribed{false};
  std::atomic<int> calls_after{0};
  std::atomic<int> first_count{0};
  auto first = client.subscribe([&](const HandEvent&) {
    if (unsubscribed) ++calls_after;
    ++first_count;
    std::this_thread::sleep_for(std::chrono::microseconds(200));  // be mid-callback often
  });
  EventLog keeps_listening;
  auto second = client.subscribe([&](const HandEvent& e) { keeps_listening.add(e); });

  std::atomic<bool> stop{false};
  std::thread publisher([&] {
    while (!stop) fake.publish_event(1, msg::EVENT_ARRIVED);
  });
  EXPECT_TRUE(keeps_listening.wait_for([](const auto& e) { return e.size() >= 20; }));
  first.unsubscribe();
  unsubscribed = true;
  EXPECT_FALSE(first.active());
  const int seen_before = first_count;
  // Events keep coming to the other subscriber; none reaches the first.
  const std::size_t now = keeps_listening.events().size();
  EXPECT_TRUE(keeps_listening.wait_for([&](const auto& e) { return e.size() >= now + 50; }));
  stop = true;
  publisher.join();
  EXPECT_EQ(calls_after, 0);
  EXPECT_EQ(first_count, seen_before);
}

TEST(ClientTest, ACallbackMayUnsubscribeItself) {
  FakeService fake(test_domain(), service_name());
  Client client(options());
  ASSERT_TRUE(client.wait_for_service(service_name(), kDeadline));
  std::atomic<int> calls{0};
  Subscription self;
  self = client.subscribe([&](const HandEvent&) {
    ++calls;
    self.unsubscribe();
  });
  EventLog other;
  auto subscription = client.subscribe([&](const HandEvent& e) { other.add(e); });
  for (int i = 0; i < 5; ++i) fake.publish_event(1, msg::EVENT_ARRIVED);
  EXPECT_TRUE(other.wait_for([](const auto& e) { return e.size() >= 5; }));
  EXPECT_EQ(calls, 1);
}

TEST(ClientTest, StatusSubscriptionGetsKnownStatusesThenUpdates) {
  FakeService fake(test_domain(), service_name());
  Client client(options());
  ASSERT_TRUE(client.wait_for_service(service_name(), kDeadline));
  ASSERT_TRUE(client.wait_for_statuses(kDeadline));
  std::mutex mutex;
  std::condition_variable changed;
  std::vector<HandStatus> seen;
  auto subscription = client.subscribe_status(
      [&](const HandStatus& s) {
        {
          std::lock_guard lock(mutex);
          seen.push_back(s);
        }
        changed.notify_all();
      },
      hand_address(1));
  fake.publish_status(1, true, 55);
  std::unique_lock lock(mutex);
  ASSERT_TRUE(changed.wait_for(lock, kDeadline,
                               [&] { return !seen.empty() && seen.back().position == 55; }));
  EXPECT_EQ(seen.front().address, hand_address(1));
  EXPECT_EQ(seen.front().position, 100);  // the status known before subscribing came first
  for (const auto& s : seen) EXPECT_EQ(s.address, hand_address(1));
}

TEST(ClientTest, SeveralThreadsDriveSeveralHandsThroughOneClient) {
  FakeService fake(test_domain(), service_name(), {1, 2, 3, 4});
  Client client(options());
  ASSERT_TRUE(client.wait_for_service(service_name(), kDeadline));
  std::atomic<int> wrong{0};
  std::vector<std::thread> threads;
  for (std::uint16_t id = 1; id <= 4; ++id) {
    threads.emplace_back([&, id] {
      Hand hand = client.hand(hand_address(id));
      for (int i = 0; i < 25; ++i) {
        const std::int32_t position = (id * 20 + i) % 101;
        const Reply reply = hand.move_to(position);
        if (!reply || reply.value != position) ++wrong;
      }
    });
  }
  for (auto& t : threads) t.join();
  EXPECT_EQ(wrong, 0);
  const auto requests = fake.wait_requests(100, kDeadline);
  EXPECT_EQ(requests.size(), 100U);
}

TEST(ClientTest, OutOfRangeValuesAreRefusedBeforeAnythingIsSent) {
  FakeService fake(test_domain(), service_name());
  Client client(options());
  auto hand = client.wait_for_hand(hand_address(1).to_string(), kDeadline);
  ASSERT_TRUE(hand);
  EXPECT_EQ(hand->move_to(101).code, Code::invalid_argument);
  const Reply force = hand->set_force(50, 10);
  EXPECT_EQ(force.code, Code::invalid_argument);
  EXPECT_THAT(force.message, HasSubstr("SET_OPENING_FORCE value 10"));
  EXPECT_TRUE(hand->set_force(50, 60));
  // Requests arrive in order: the first the service saw is the valid set_force.
  const auto requests = fake.wait_requests(2, kDeadline);
  ASSERT_EQ(requests.size(), 2U);
  EXPECT_EQ(requests[0].command(), msg::SET_CLOSING_FORCE);
  EXPECT_EQ(requests[0].value(), 50);
  EXPECT_EQ(requests[1].command(), msg::SET_OPENING_FORCE);
  EXPECT_EQ(requests[1].value(), 60);
}

TEST(ClientTest, ClosingTheClientEndsPendingCallsAndOrphanHandsFailCleanly) {
  FakeService fake(test_domain(), service_name());
  fake.set_handler([](const msg::CommandRequest&) { return std::vector<msg::CommandReply>{}; });
  auto client = std::make_unique<Client>(options());
  auto hand = client->wait_for_hand(hand_address(1).to_string(), kDeadline);
  ASSERT_TRUE(hand);
  Hand orphan = *hand;
  auto pending = orphan.release_async(100);
  ASSERT_EQ(fake.wait_requests(1, kDeadline).size(), 1U);
  client.reset();
  ASSERT_TRUE(is_ready(pending));
  EXPECT_EQ(pending.get().code, Code::not_connected);
  EXPECT_EQ(orphan.stop().code, Code::not_connected);
}

TEST(ClientTest, BadSetUpIsReportedNotThrown) {
  ClientOptions bad = options();
  bad.domain = 500;
  Client client(bad);
  EXPECT_FALSE(client.connected());
  EXPECT_THAT(client.error(), HasSubstr("out of range"));
  const Reply reply = client.hand(hand_address(1)).initialize();
  EXPECT_EQ(reply.code, Code::not_connected);
  EXPECT_THAT(reply.message, HasSubstr("out of range"));

  ClientOptions no_file = options();
  no_file.xml_profile_file = "/nonexistent/profiles.xml";
  EXPECT_THAT(Client(no_file).error(), HasSubstr("XML"));
  ClientOptions bad_server = options();
  bad_server.discovery_servers = {"10.0.0.1:port"};
  EXPECT_THAT(Client(bad_server).error(), HasSubstr("discovery server '10.0.0.1:port'"));
}

// ---------------------------------------------------------------------------
// The callback form of the commands: each callback runs once, on the client's
// callback thread after the status its reply carried, may call the client
// (blocking calls too), and runs even when the call ends without a reply.

TEST(CompletionCallbackTest, RunsOnTheCallbackThreadAfterTheStatusItsReplyCarried) {
  FakeService fake(test_domain(), service_name());
  fake.set_handler([&](const msg::CommandRequest& r) {
    auto reply = reply_to(r);
    if (r.command() == msg::MOVE) reply.status(fake.make_status(1, true, r.value()));
    return std::vector{reply};
  });
  Client client(options());
  auto hand = client.wait_for_hand(hand_address(1).to_string(), kDeadline);
  ASSERT_TRUE(hand) << hand.message();
  Heard log;
  Subscription statuses = client.subscribe_status([&](const HandStatus& s) {
    if (s.position == 60) log.add("status 60");
  });
  Hand target = *hand;
  hand->move_to_async(60, [&](Reply reply) {
    // A blocking call from the callback: its reply is not held up by it.
    const Reply read = target.read(reg::position);
    log.add("move " + std::string(to_string(reply.code)) + ", then read " +
            std::string(to_string(read.code)));
  });
  const auto seen = log.wait_for(2);
  ASSERT_GE(seen.size(), 2U);
  EXPECT_EQ(seen[0], "status 60");
  EXPECT_EQ(seen[1], "move OK, then read OK");
  EXPECT_EQ(log.threads()[0], log.threads()[1]);
  EXPECT_NE(log.threads()[1], std::this_thread::get_id());
}

TEST(CompletionCallbackTest, ARefusedCallAndAClosedClientStillCallBackOnce) {
  FakeService fake(test_domain(), service_name());
  fake.set_handler([](const msg::CommandRequest&) { return std::vector<msg::CommandReply>{}; });
  auto client = std::make_unique<Client>(options());
  auto hand = client->wait_for_hand(hand_address(1).to_string(), kDeadline);
  ASSERT_TRUE(hand) << hand.message();
  Hand orphan = *hand;
  Heard log;
  orphan.move_to_async(250, [&](Reply r) { log.add(std::string(to_string(r.code))); });
  ASSERT_EQ(log.wait_for(1).size(), 1U);
  EXPECT_EQ(log.items()[0], "INVALID_ARGUMENT");

  orphan.release_async(100, [&](Reply r) { log.add(std::string(to_string(r.code))); });
  ASSERT_EQ(fake.wait_requests(1, kDeadline).size(), 1U);
  client.reset();  // its pending call's callback has run when this returns
  EXPECT_EQ(log.items().size(), 2U);
  EXPECT_EQ(log.items().back(), "NOT_CONNECTED");
  orphan.stop_async([&](Reply r) { log.add(std::string(to_string(r.code))); });
  ASSERT_EQ(log.items().size(), 3U);  // at once, on this thread
  EXPECT_EQ(log.items().back(), "NOT_CONNECTED");
  EXPECT_EQ(log.threads().back(), std::this_thread::get_id());
}

TEST(CompletionCallbackTest, ACallbackThatThrowsDoesNotStopTheNextOne) {
  FakeService fake(test_domain(), service_name());
  Client client(options());
  auto hand = client.wait_for_hand(hand_address(1).to_string(), kDeadline);
  ASSERT_TRUE(hand) << hand.message();
  Heard log;
  hand->stop_async([](const Reply&) { throw std::runtime_error("the user's own"); });
  hand->stop_async([&](Reply r) { log.add(std::string(to_string(r.code))); });
  ASSERT_EQ(log.wait_for(1).size(), 1U);
  EXPECT_EQ(log.items()[0], "OK");
}

}  // namespace
}  // namespace dh3
