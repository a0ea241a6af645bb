// RequestHandler without DDS and without a running bus: the answers it gives
// at once (refusals, shutdown, leases), recorded by a ReplySink.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <optional>

#include "dh3/hand/hand_roster.hpp"
#include "expiry_timer.hpp"
#include "group_commands.hpp"
#include "hand_directory.hpp"
#include "lease_table.hpp"
#include "recording_reply_sink.hpp"
#include "request_handler.hpp"
#include "status_publisher.hpp"

namespace dh3::dds {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
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
  /// Handles the request, sent by `caller` (by default the participant its
  /// client_id names, shown by that id), and returns its one reply.
  msg::CommandReply answer(msg::CommandRequest r, bool stopping = false,
                           std::optional<Caller> caller = std::nullopt) {
    const std::size_t before = sink_.replies.size();
    if (!caller) caller = Caller{r.client_id(), r.client_id()};
    handler_.handle(r, *caller, stopping);
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
  ClientShare share_;
  RequestHandler handler_{
      {options_, directory_, leases_, schedulers_, statuses_, sink_, timer_, share_}};
};

TEST_F(RequestHandlerTest, AnotherServicesRequestIsNotAnswered) {
  auto r = request(msg::ACQUIRE_LEASE, 2000);
  r.hand().service("other");
  handler_.handle(r, Caller{"alice", "alice"}, false);
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

// A participant's identity is the writer of its request, not the client_id
// it writes: another participant naming the holder's id is still another.
TEST_F(RequestHandlerTest, AClientIdNamingTheHolderFromAnotherParticipantIsDenied) {
  const Caller holder{"0a1b2c", "dh3-web@cell-pc"};
  const Caller forger{"9f8e7d", "cyclone_client@laptop"};
  const auto taken = answer(request(msg::ACQUIRE_LEASE, 2000, holder.id), false, holder);
  ASSERT_EQ(taken.code(), msg::OK);
  for (const auto command : {msg::MOVE, msg::ACQUIRE_LEASE, msg::RENEW_LEASE, msg::RELEASE_LEASE}) {
    const auto forged =
        answer(request(command, command == msg::MOVE ? 30 : 2000, "0A.1B.2C"), false, forger);
    EXPECT_EQ(forged.code(), msg::DENIED) << command;
    EXPECT_THAT(forged.message(), HasSubstr("is leased by client 'dh3-web@cell-pc'")) << command;
    EXPECT_THAT(forged.message(), HasSubstr("a lease belongs to the participant that took it"))
        << command;
    EXPECT_EQ(forged.lease_holder(), "dh3-web@cell-pc") << command;
    EXPECT_EQ(forged.client_id(), "0A.1B.2C") << command;  // still addressed as written
  }
  EXPECT_EQ(leases_.holder(kHand), "dh3-web@cell-pc");
  EXPECT_TRUE(leases_.held_by(kHand, holder.id));
}

TEST_F(RequestHandlerTest, ThePublishedHolderIsTheParticipantsNameNeverItsId) {
  const Caller alice{"0a1b2c", "dh3ctl@cell-pc"};
  const auto reply = answer(request(msg::ACQUIRE_LEASE, 2000, "any string"), false, alice);
  EXPECT_EQ(reply.code(), msg::OK);
  EXPECT_EQ(reply.lease_holder(), "dh3ctl@cell-pc");
  EXPECT_EQ(status().lease_holder(), "dh3ctl@cell-pc");
  // The holder renews and releases whatever its requests' client_id says.
  EXPECT_EQ(answer(request(msg::RENEW_LEASE, 2000, "another string"), false, alice).code(),
            msg::OK);
  const auto bob = answer(request(msg::MOVE, 30, "bob"));
  EXPECT_THAT(bob.message(), HasSubstr("'dh3ctl@cell-pc'"));
  EXPECT_THAT(bob.message(), Not(HasSubstr(alice.id)));
  EXPECT_THAT(bob.message(), Not(HasSubstr("lease belongs")));  // it claimed nothing
  EXPECT_EQ(answer(request(msg::RELEASE_LEASE, 0, "x"), false, alice).code(), msg::OK);
  EXPECT_EQ(status().lease_holder(), "");
}

TEST_F(RequestHandlerTest, UnderAccessControlAdminCommandsComeOnlyOnTheAdminTopic) {
  options_.allow_admin = true;
  handler_.set_access_control(true);
  for (const auto command : {msg::SET_CAN_ID, msg::SET_BAUD_RATE}) {
    const auto reply = answer(request(command, 2));  // on the command request topic
    EXPECT_EQ(reply.code(), msg::DENIED) << command;
    EXPECT_THAT(reply.message(), HasSubstr("only on dh3/admin_request")) << command;
    EXPECT_THAT(reply.message(), HasSubstr("it came on dh3/command_request")) << command;
  }
  // The admin topic carries nothing but administrative commands.
  auto move = request(msg::MOVE, 30);
  handler_.handle(move, Caller{"alice", "alice"}, false, RequestTopic::admin);
  ASSERT_FALSE(sink_.replies.empty());
  EXPECT_EQ(sink_.replies.back().code(), msg::INVALID_ARGUMENT);
  EXPECT_THAT(sink_.replies.back().message(), HasSubstr("takes only SET_CAN_ID and SET_BAUD_RATE"));
}

TEST_F(RequestHandlerTest, WithoutAllowAdminTheAdminTopicIsRefusedToo) {
  handler_.set_access_control(true);
  auto set_id = request(msg::SET_CAN_ID, 2);
  handler_.handle(set_id, Caller{"alice", "alice"}, false, RequestTopic::admin);
  ASSERT_FALSE(sink_.replies.empty());
  EXPECT_EQ(sink_.replies.back().code(), msg::DENIED);
  EXPECT_THAT(sink_.replies.back().message(), HasSubstr("start it with --allow-admin"));
}

TEST_F(RequestHandlerTest, AClientBeyondItsRateIsAnsweredBusySayingWhy) {
  ClientRate rate(clock_, 2);
  handler_.set_rate(&rate);
  EXPECT_EQ(answer(request(msg::ACQUIRE_LEASE, 2000)).code(), msg::OK);
  EXPECT_EQ(answer(request(msg::RENEW_LEASE, 2000)).code(), msg::OK);
  const auto third = answer(request(msg::RENEW_LEASE, 2000));
  EXPECT_EQ(third.code(), msg::BUSY);
  EXPECT_THAT(third.message(), HasSubstr("sends more than 2 requests a second"));
  // Another client has a rate of its own.
  EXPECT_EQ(answer(request(msg::MOVE, 30, "bob")).code(), msg::DENIED);  // alice's lease
  clock_.advance(500ms);
  EXPECT_EQ(answer(request(msg::RELEASE_LEASE)).code(), msg::OK);
}

/// A group request for hand 1 and 2 of bus0 that its checks refuse as a
/// whole (no bus runs here), so that only the rate decides whether it is BUSY.
msg::GroupRequest refused_group(const std::string& client) {
  msg::GroupRequest r;
  r.client_id(client);
  r.request_seq(8);
  r.command(msg::ACQUIRE_LEASE);  // no group command
  for (const std::uint8_t can_id : {1, 2}) {
    msg::HandAddress& hand = r.hands().emplace_back();
    hand.bus("bus0");
    hand.can_id(can_id);
  }
  return r;
}

TEST_F(RequestHandlerTest, AGroupCountsInItsCallersRateAsASingleRequestDoes) {
  ClientRate rate(clock_, 3);
  handler_.set_rate(&rate);
  GroupCommands groups{{options_, clock_, directory_, leases_, schedulers_, sink_, share_, rate}};
  const Caller alice{"alice", "alice@cell-pc"};
  auto group = refused_group("alice");
  groups.handle(group, alice, false);
  ASSERT_EQ(sink_.group_replies.size(), 1U);
  EXPECT_NE(sink_.group_replies.back().code(), msg::BUSY);  // its checks' answer
  EXPECT_EQ(answer(request(msg::ACQUIRE_LEASE, 2000)).code(), msg::OK);
  group = refused_group("alice");
  groups.handle(group, alice, false);
  EXPECT_NE(sink_.group_replies.back().code(), msg::BUSY);
  // Two groups and a request: the rate of 3 is spent, by either kind.
  EXPECT_EQ(answer(request(msg::RENEW_LEASE, 2000)).code(), msg::BUSY);
  group = refused_group("alice");
  groups.handle(group, alice, false);
  ASSERT_EQ(sink_.group_replies.size(), 3U);
  const msg::GroupReply& busy = sink_.group_replies.back();
  EXPECT_EQ(busy.code(), msg::BUSY);
  EXPECT_THAT(busy.message(), HasSubstr("client 'alice@cell-pc' (participant alice) sends more "
                                        "than 3 requests a second"));
  for (const auto& member : busy.results()) EXPECT_EQ(member.code(), msg::CANCELLED);
  EXPECT_EQ(rate.refused(), 2U);
  // Another client's groups have a rate of their own; alice's comes back.
  group = refused_group("bob");
  groups.handle(group, Caller{"bob", "bob"}, false);
  EXPECT_NE(sink_.group_replies.back().code(), msg::BUSY);
  clock_.advance(400ms);
  group = refused_group("alice");
  groups.handle(group, alice, false);
  EXPECT_NE(sink_.group_replies.back().code(), msg::BUSY);
}

}  // namespace
}  // namespace dh3::dds
