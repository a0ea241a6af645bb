// GroupCommands' summary of its members' results (summarize_group): the
// part of a group's answer that needs no bus and no DDS.

#include <gtest/gtest.h>

#include <string>

#include "group_commands.hpp"

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

}  // namespace
}  // namespace dh3::dds
