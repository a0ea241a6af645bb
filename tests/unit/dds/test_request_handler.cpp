// RequestHandler without DDS and without a running bus: the answers it gives
// at once (refusals, shutdown, leases), recorded by a ReplySink.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>

#include "dh3/hand/hand_roster.hpp"
#include "expiry_timer.hpp"
#include "hand_directory.hpp"
#include "lease_table.hpp"
#include "recording_reply_sink.hpp"
#include "request_handler.hpp"
#include "status_publisher.hpp"

namespace dh3::dds {
namespace {

using ::testing::HasSubstr;
using namespace std::chrono_literals;

constexpr HandKey kHand{0, 1};

class RequestHandlerTest : public ::testing::Test {
 protected:
  RequestHandlerTest() {
    directory_.add_bus("bus0", roster_);
    statuses_.add_bus("bus0", "sim:1", {1});
    hand::HandState state;
    state.can_id = kHand.can_id;
    state.online = true;
    statuses_.on_state(kHand.bus, state);
    statuses_.send_held(kHand.bus, kHand.can_id);
  }

  static msg::CommandRequest request(msg::CommandType command, std::int32_t value = 0,
                                     std::string client = "alice", std::uint16_t can_id = 1) {
    msg::CommandRequest r;
    r.client_id(std::move(client));
    r.request_seq(7);
    r.hand().service("dh3");
    r.hand().bus("bus0");
    r.hand().can_id(can_id);
    r.command(command);
    r.value(value);
    return r;
  }
  /// Handles the request and returns its one reply.
  msg::CommandReply answer(msg::CommandRequest r, bool stopping = false) {
    const std::size_t before = sink_.replies.size();
    handler_.handle(r, stopping);
    EXPECT_EQ(sink_.replies.size(), before + 1);
    return sink_.replies.empty() ? msg::CommandReply{} : sink_.replies.back();
  }
  /// The status sample a reply about the hand would carry now.
  msg::HandStatus status() {
    msg::CommandReply reply;
    statuses_.attach_to(reply, kHand.bus, kHand.can_id);
    return reply.status();
  }

  ServiceOptions options_;
  FakeClock clock_;
  LeaseTable leases_{clock_};
  hand::HandRoster roster_{std::vector<hand::HandConfig>{{1, "left"}}};
  HandDirectory directory_;
  Schedulers schedulers_;  // no bus runs: only answers given at once are tested
  StatusPublisher statuses_{options_, clock_, leases_, directory_};
  RecordingReplySink sink_;
  ExpiryTimer timer_{[] { return std::optional<TimePoint>{}; }, [] {}};
  RequestHandler handler_{{options_, directory_, leases_, schedulers_, statuses_, sink_, timer_}};
};

TEST_F(RequestHandlerTest, AnotherServicesRequestIsNotAnswered) {
  auto r = request(msg::ACQUIRE_LEASE, 2000);
  r.hand().service("other");
  handler_.handle(r, false);
  EXPECT_TRUE(sink_.replies.empty());
  EXPECT_EQ(leases_.holder(kHand), "");
}

TEST_F(RequestHandlerTest, WhileStoppingEveryRequestIsCancelled) {
  const auto reply = answer(request(msg::ACQUIRE_LEASE, 2000), true);
  EXPECT_EQ(reply.code(), msg::CANCELLED);
  EXPECT_THAT(reply.message(), HasSubstr("the service is shutting down"));
  EXPECT_EQ(reply.client_id(), "alice");
  EXPECT_EQ(reply.request_seq(), 7u);
  EXPECT_EQ(leases_.holder(kHand), "");
}

TEST_F(RequestHandlerTest, UnknownHandIsRefusedWithTheValidationsAnswer) {
  const auto reply = answer(request(msg::ACQUIRE_LEASE, 2000, "alice", 9));
  EXPECT_EQ(reply.code(), msg::UNKNOWN_HAND);
  EXPECT_EQ(reply.hand().can_id(), 9);
}

TEST_F(RequestHandlerTest, AcquiredLeaseIsInTheRepliesStatusAndThenPublished) {
  const auto reply = answer(request(msg::ACQUIRE_LEASE, 2000));
  EXPECT_EQ(reply.code(), msg::OK);
  EXPECT_EQ(reply.value(), 2000);
  EXPECT_EQ(reply.lease_holder(), "alice");
  EXPECT_EQ(reply.status().lease_holder(), "alice");
  EXPECT_EQ(reply.status().update_seq(), 2u);
  EXPECT_EQ(leases_.holder(kHand), "alice");
  // Renewing changes no holder: the reply carries the same sample.
  const auto renewed = answer(request(msg::RENEW_LEASE, 2000));
  EXPECT_EQ(renewed.code(), msg::OK);
  EXPECT_EQ(renewed.status().update_seq(), 2u);
}

TEST_F(RequestHandlerTest, AnotherClientsLeaseDeniesMotionAndLeases) {
  answer(request(msg::ACQUIRE_LEASE, 2000));
  const auto move = answer(request(msg::MOVE, 50, "bob"));
  EXPECT_EQ(move.code(), msg::DENIED);
  EXPECT_EQ(move.lease_holder(), "alice");
  EXPECT_THAT(move.message(), HasSubstr("is leased by client 'alice'"));
  EXPECT_EQ(move.status().lease_holder(), "alice");
  const auto acquire = answer(request(msg::ACQUIRE_LEASE, 2000, "bob"));
  EXPECT_EQ(acquire.code(), msg::DENIED);
  EXPECT_EQ(acquire.lease_holder(), "alice");
}

TEST_F(RequestHandlerTest, RenewWithoutALeaseIsDeniedAndReleaseFreesTheHand) {
  const auto renew = answer(request(msg::RENEW_LEASE, 2000));
  EXPECT_EQ(renew.code(), msg::DENIED);
  EXPECT_THAT(renew.message(), HasSubstr("holds no lease"));
  answer(request(msg::ACQUIRE_LEASE, 2000));
  const auto release = answer(request(msg::RELEASE_LEASE));
  EXPECT_EQ(release.code(), msg::OK);
  EXPECT_EQ(release.lease_holder(), "");
  EXPECT_EQ(leases_.holder(kHand), "");
  EXPECT_EQ(status().lease_holder(), "");
}

}  // namespace
}  // namespace dh3::dds
