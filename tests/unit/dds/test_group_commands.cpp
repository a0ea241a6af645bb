// GroupCommands without DDS and without a running bus: the summary of its
// members' results (summarize_group) and the refusals it answers at once.

#include <gtest/gtest.h>

#include <string>

#include "dh3/hand/hand_roster.hpp"
#include "group_commands.hpp"
#include "hand_directory.hpp"
#include "lease_table.hpp"
#include "recording_reply_sink.hpp"

namespace dh3::dds {
namespace {

msg::GroupReply reply_of(std::initializer_list<std::pair<msg::ResultCode, std::string>> members) {
  msg::GroupReply reply;
  std::uint8_t can_id = 1;
  for (const auto& [code, message] : members) {
    msg::GroupMemberResult& member = reply.results().emplace_back();
    member.hand().bus("bus0");
    member.hand().can_id(can_id++);
    member.code(code);
    member.message(message);
  }
  return reply;
}

TEST(GroupCommandsTest, EveryMemberOkIsOkWithoutMessage) {
  auto reply = reply_of({{msg::OK, ""}, {msg::OK, ""}});
  reply.message("stale");
  summarize_group(reply);
  EXPECT_EQ(reply.code(), msg::OK);
  EXPECT_EQ(reply.message(), "");
}

TEST(GroupCommandsTest, FirstFailureGivesTheCodeAndEveryFailureIsNamed) {
  auto reply = reply_of({{msg::OK, ""}, {msg::TIMEOUT, "no answer"}, {msg::FAILED, "motor fault"}});
  summarize_group(reply);
  EXPECT_EQ(reply.code(), msg::TIMEOUT);
  EXPECT_EQ(reply.message(), "bus0/2: TIMEOUT: no answer; bus0/3: FAILED: motor fault");
}

TEST(GroupCommandsTest, CancelledMembersHideBehindTheRootCause) {
  auto reply = reply_of({{msg::CANCELLED, "another failed"}, {msg::BUS_DOWN, "link down"}});
  summarize_group(reply);
  EXPECT_EQ(reply.code(), msg::BUS_DOWN);
  EXPECT_EQ(reply.message(), "bus0/2: BUS_DOWN: link down");
}

TEST(GroupCommandsTest, OnlyCancelledMembersAreNamed) {
  auto reply = reply_of({{msg::CANCELLED, "shutting down"}, {msg::OK, ""}});
  summarize_group(reply);
  EXPECT_EQ(reply.code(), msg::CANCELLED);
  EXPECT_EQ(reply.message(), "bus0/1: CANCELLED: shutting down");
}

const Caller kAlice{"alice", "alice"};

class GroupCommandsRefusalTest : public ::testing::Test {
 protected:
  GroupCommandsRefusalTest() { directory_.add_bus("bus0", roster_); }

  static msg::GroupRequest request(msg::CommandType command) {
    msg::GroupRequest r;
    r.client_id("alice");
    r.request_seq(9);
    r.command(command);
    r.value(50);
    for (const std::uint8_t can_id : {1, 2}) {
      msg::HandAddress& hand = r.hands().emplace_back();
      hand.bus("bus0");
      hand.can_id(can_id);
    }
    return r;
  }

  ServiceOptions options_;
  FakeClock clock_;
  LeaseTable leases_{clock_};
  hand::HandRoster roster_{std::vector<hand::HandConfig>{{1, "left"}, {2, "right"}}};
  HandDirectory directory_;
  Schedulers schedulers_;  // no bus runs: only answers given at once are tested
  RecordingReplySink sink_;
  ClientShare share_;
  ClientRate rate_{clock_, 0};  // no bound: test_request_handler.cpp tests the rate
  GroupCommands groups_{{options_, clock_, directory_, leases_, schedulers_, sink_, share_, rate_}};
};

TEST_F(GroupCommandsRefusalTest, AnotherServicesGroupIsNotAnswered) {
  auto r = request(msg::MOVE);
  r.service("other");
  groups_.handle(r, kAlice, false);
  EXPECT_TRUE(sink_.group_replies.empty());
}

TEST_F(GroupCommandsRefusalTest, WhileStoppingEveryHandIsCancelledAndNamed) {
  auto r = request(msg::MOVE);
  groups_.handle(r, kAlice, true);
  ASSERT_EQ(sink_.group_replies.size(), 1u);
  const msg::GroupReply& reply = sink_.group_replies.front();
  EXPECT_EQ(reply.code(), msg::CANCELLED);
  EXPECT_EQ(reply.message(), "the service is shutting down");
  EXPECT_EQ(reply.request_seq(), 9u);
  ASSERT_EQ(reply.results().size(), 2u);
  for (const auto& member : reply.results()) {
    EXPECT_EQ(member.code(), msg::CANCELLED);
    EXPECT_EQ(member.hand().service(), "dh3");  // filled in with the service's name
  }
}

TEST_F(GroupCommandsRefusalTest, CommandNotForGroupsIsRefusedAsAWhole) {
  auto r = request(msg::ACQUIRE_LEASE);
  groups_.handle(r, kAlice, false);
  ASSERT_EQ(sink_.group_replies.size(), 1u);
  const msg::GroupReply& reply = sink_.group_replies.front();
  EXPECT_NE(reply.code(), msg::OK);
  EXPECT_FALSE(reply.message().empty());
  for (const auto& member : reply.results()) {
    EXPECT_EQ(member.code(), msg::CANCELLED);
    EXPECT_EQ(member.message(), reply.message());
  }
}

}  // namespace
}  // namespace dh3::dds
