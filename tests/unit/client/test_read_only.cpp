// A read-only client, without DDS Security: ClientCore is told that access
// control refused it the command endpoints (test::RefusingEndpoints, an EndpointCreator), which
// is what Fast DDS does to a "monitor" identity. It must stay connected, know
// hands and services from what it may read, and end commands at once with
// DENIED. test_client_security covers the same with real credentials.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <future>
#include <memory>
#include <mutex>
#include <vector>

#include "client_core.hpp"
#include "fake_service.hpp"
#include "refusing_endpoints.hpp"
#include "support/test_domain.hpp"

namespace dh3 {
namespace {

using detail::ClientCore;
using detail::ClientEndpoint;
using test::RefusingEndpoints;
using ::testing::HasSubstr;

constexpr std::chrono::seconds kDeadline{15};

using test::test_domain;
std::string service_name() {
  return "ro" + std::to_string(::getpid());
}

ClientOptions options() {
  ClientOptions o;
  o.domain = test_domain();
  o.default_timeout = kDeadline;
  return o;
}

HandSpec spec(const std::string& text) {
  auto parsed = parse_hand_spec(text);
  EXPECT_TRUE(parsed) << parsed.message();
  return *parsed;
}

TEST(ReadOnlyClient, RefusedCommandEndpointsLeaveAConnectedClientThatWatches) {
  test::FakeService fake(test_domain(), service_name());
  ASSERT_TRUE(fake.ok());
  auto core = std::make_shared<ClientCore>(
      options(), RefusingEndpoints({ClientEndpoint::request_writer, ClientEndpoint::reply_reader,
                                    ClientEndpoint::info_reader}));
  ASSERT_TRUE(core->connected()) << core->error();
  EXPECT_TRUE(core->read_only());

  // Hands are known from their statuses, by full address and by name.
  const auto found = core->wait_for_hand(spec(service_name() + "/bus0/1"), kDeadline);
  ASSERT_TRUE(found) << found.message();
  const auto by_name = core->wait_for_hand(spec(service_name() + "/hand2"), kDeadline);
  ASSERT_TRUE(by_name) << by_name.message();
  EXPECT_EQ(by_name->can_id, 2);

  // The service is ready (its events reach us) without any ServiceInfo.
  const auto service = core->wait_for_service(service_name(), kDeadline);
  ASSERT_TRUE(service) << service.message();
  EXPECT_TRUE(service->ready);
  EXPECT_TRUE(service->buses.empty());
  EXPECT_TRUE(core->wait_for_statuses(kDeadline));

  // Events arrive.
  std::mutex mutex;
  std::condition_variable cv;
  std::vector<HandEvent> events;
  auto subscription = core->subscribe_events(
      [&](const HandEvent& e) {
        std::lock_guard lock(mutex);
        events.push_back(e);
        cv.notify_all();
      },
      std::nullopt);
  // Events are volatile: one published before the event reader and writer
  // have matched is gone, so publish again until one arrives.
  {
    const auto give_up = std::chrono::steady_clock::now() + kDeadline;
    std::unique_lock lock(mutex);
    while (events.empty() && std::chrono::steady_clock::now() < give_up) {
      lock.unlock();
      fake.publish_event(1, msg::EVENT_GRASPED, 37);
      lock.lock();
      cv.wait_for(lock, std::chrono::milliseconds(250), [&] { return !events.empty(); });
    }
    ASSERT_FALSE(events.empty()) << "no event arrived";
    EXPECT_EQ(events.front().kind, EventKind::grasped);
  }
  core->unsubscribe(subscription);

  // A command ends before call() returns: nothing to wait for, nothing sent.
  auto reply = core->call(*found, msg::MOVE, 50, 0, kDeadline);
  ASSERT_EQ(reply.wait_for(std::chrono::seconds(0)), std::future_status::ready);
  const Reply r = reply.get();
  EXPECT_EQ(r.code, Code::denied);
  EXPECT_THAT(r.message, HasSubstr("not permitted to publish command requests"));
  // Statuses still flow after the refused command.
  fake.publish_status(1, true, 12);
  const auto moved = core->wait_status(
      *found, [](const HandStatus& s) { return s.position == 12; }, kDeadline);
  EXPECT_TRUE(moved);
}

TEST(ReadOnlyClient, OutOfRangeValuesAreStillInvalidArguments) {
  auto core = std::make_shared<ClientCore>(
      options(), RefusingEndpoints({ClientEndpoint::request_writer, ClientEndpoint::reply_reader}));
  ASSERT_TRUE(core->connected()) << core->error();
  EXPECT_TRUE(core->read_only());
  const HandAddress hand{service_name(), "bus0", 1};
  EXPECT_EQ(core->call(hand, msg::MOVE, 500, 0, kDeadline).get().code, Code::invalid_argument);
  EXPECT_EQ(core->call(hand, msg::MOVE, 50, 0, kDeadline).get().code, Code::denied);
}

// An identity that may command but not read service infos: commands work.
TEST(ReadOnlyClient, WithoutTheInfoReaderCommandsStillWork) {
  test::FakeService fake(test_domain(), service_name());
  ASSERT_TRUE(fake.ok());
  auto core =
      std::make_shared<ClientCore>(options(), RefusingEndpoints({ClientEndpoint::info_reader}));
  ASSERT_TRUE(core->connected()) << core->error();
  EXPECT_FALSE(core->read_only());
  const auto service = core->wait_for_service(service_name(), kDeadline);
  ASSERT_TRUE(service) << service.message();
  const Reply r = core->call({service_name(), "bus0", 1}, msg::MOVE, 50, 0, kDeadline).get();
  EXPECT_EQ(r.code, Code::ok) << r.message;
  EXPECT_EQ(fake.wait_requests(1, kDeadline).size(), 1U);
}

}  // namespace
}  // namespace dh3
