// All or none: a group request is checked hand by hand, and every hand that
// fails is named with its own code and reason.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <map>

#include "group_validation.hpp"

namespace dh3::dds {
namespace {

using ::testing::HasSubstr;

class GroupValidationTest : public ::testing::Test {
 protected:
  GroupValidationTest() {
    directory_.add_bus("bus0", bus0_);
    directory_.add_bus("bus1", bus1_);
    // Every hand up, online and initialized unless a test says otherwise.
    for (auto key : {std::pair<std::uint16_t, std::uint8_t>{0, 1}, {0, 2}, {0, 3}, {1, 5}}) {
      facts_[key] = MemberFacts{true, true, true, std::nullopt};
    }
  }

  static msg::HandAddress hand(std::string bus, std::uint16_t can_id) {
    msg::HandAddress a;
    a.bus(std::move(bus));
    a.can_id(can_id);
    return a;
  }

  static msg::GroupRequest group(msg::CommandType command, std::int32_t value,
                                 std::vector<msg::HandAddress> hands) {
    msg::GroupRequest r;
    r.client_id("0102030405060708090a0b0c");
    r.request_seq(9);
    r.service("dh3");
    r.hands(std::move(hands));
    r.command(command);
    r.value(value);
    return r;
  }

  Result<std::vector<ValidRequest>, GroupRefusal> check(const msg::GroupRequest& r) {
    return validate_group(r, directory_, [this](std::uint16_t bus, std::uint8_t can_id) {
      return facts_[{bus, can_id}];
    });
  }

  hand::HandRoster bus0_{{{1, "left"}, {2, "right"}, {3, ""}}};
  hand::HandRoster bus1_{{{5, ""}}};
  HandDirectory directory_;
  std::map<std::pair<std::uint16_t, std::uint8_t>, MemberFacts> facts_;
};

TEST_F(GroupValidationTest, HandsOnTwoBusesPassInTheRequestsOrder) {
  const auto result = check(group(msg::GRASP, 50, {hand("bus1", 5), hand("bus0", 2)}));
  ASSERT_TRUE(result.ok());
  ASSERT_EQ(result->size(), 2U);
  EXPECT_EQ((*result)[0].bus, 1);
  EXPECT_EQ((*result)[0].can_id, 5);
  EXPECT_EQ((*result)[1].can_id, 2);
  EXPECT_EQ((*result)[1].command.kind, hand::CommandKind::grasp);
  EXPECT_EQ((*result)[1].command.value, 50);
}

TEST_F(GroupValidationTest, EveryFailingHandIsNamedWithItsOwnReason) {
  facts_[{0, 2}].lease_blocker = "other-client";
  facts_[{0, 3}].initialized = false;
  facts_[{1, 5}].online = false;
  const auto result = check(
      group(msg::MOVE, 40, {hand("bus0", 1), hand("bus0", 2), hand("bus0", 3), hand("bus1", 5)}));
  ASSERT_FALSE(result.ok());
  const auto& members = result.error().members;
  ASSERT_EQ(members.size(), 3U);
  EXPECT_EQ(members[0].index, 1U);
  EXPECT_EQ(members[0].why.code, msg::DENIED);
  EXPECT_THAT(members[0].why.message, HasSubstr("other-client"));
  EXPECT_EQ(members[1].index, 2U);
  EXPECT_EQ(members[1].why.code, msg::NOT_INITIALIZED);
  EXPECT_EQ(members[2].index, 3U);
  EXPECT_EQ(members[2].why.code, msg::TIMEOUT);
  EXPECT_THAT(members[2].why.message, HasSubstr("offline"));
}

TEST_F(GroupValidationTest, AClientIdNamingTheHolderIsToldALeaseIsTheParticipants) {
  facts_[{0, 2}].lease_blocker = "dh3-web@cell-pc";
  facts_[{0, 2}].client_id_names_blocker = true;
  const auto result = check(group(msg::MOVE, 40, {hand("bus0", 1), hand("bus0", 2)}));
  ASSERT_FALSE(result.ok());
  ASSERT_EQ(result.error().members.size(), 1U);
  const Rejection& why = result.error().members[0].why;
  EXPECT_EQ(why.code, msg::DENIED);
  EXPECT_THAT(why.message, HasSubstr("'dh3-web@cell-pc'"));
  EXPECT_THAT(why.message, HasSubstr("a lease belongs to the participant that took it"));
}

TEST_F(GroupValidationTest, OneValueOutOfRangeRefusesTheGroup) {
  const auto result = check(group(msg::GRASP, 10, {hand("bus0", 1), hand("bus0", 2)}));
  ASSERT_FALSE(result.ok());
  ASSERT_EQ(result.error().members.size(), 2U);
  EXPECT_EQ(result.error().members[0].why.code, msg::INVALID_ARGUMENT);
}

TEST_F(GroupValidationTest, UnknownHandDownBusAndDuplicateAreRefused) {
  facts_[{1, 5}].link_up = false;
  const auto result = check(
      group(msg::RELEASE, 100, {hand("bus0", 1), hand("bus0", 9), hand("bus1", 5), hand("bus0", 1)}));
  ASSERT_FALSE(result.ok());
  const auto& members = result.error().members;
  ASSERT_EQ(members.size(), 3U);
  EXPECT_EQ(members[0].why.code, msg::UNKNOWN_HAND);
  EXPECT_EQ(members[1].why.code, msg::BUS_DOWN);
  EXPECT_EQ(members[2].index, 3U);
  EXPECT_THAT(members[2].why.message, HasSubstr("twice"));
}

TEST_F(GroupValidationTest, InitializeAndForcesNeedNoInitializedHand) {
  facts_[{0, 1}].initialized = false;
  EXPECT_TRUE(check(group(msg::INITIALIZE, 0, {hand("bus0", 1), hand("bus0", 2)})).ok());
  EXPECT_TRUE(check(group(msg::SET_CLOSING_FORCE, 30, {hand("bus0", 1)})).ok());
  EXPECT_FALSE(check(group(msg::ROTATE, 30, {hand("bus0", 1)})).ok());
}

TEST_F(GroupValidationTest, OnlyMotionCommandsAndSizesWithinTheLimitAreGroups) {
  const auto stop = check(group(msg::STOP, 0, {hand("bus0", 1)}));
  ASSERT_FALSE(stop.ok());
  ASSERT_TRUE(stop.error().whole.has_value());
  EXPECT_EQ(stop.error().whole->code, msg::INVALID_ARGUMENT);
  const auto empty = check(group(msg::MOVE, 10, {}));
  ASSERT_FALSE(empty.ok());
  EXPECT_TRUE(empty.error().whole.has_value());
}

}  // namespace
}  // namespace dh3::dds
