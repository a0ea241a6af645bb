// Between the wire types and the public ones: every result code maps to the
// same-named public code, replies keep what the caller needs, and the local
// checks refuse what the service would refuse, naming the range.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "conversions.hpp"

namespace dh3::detail {
namespace {

using ::testing::HasSubstr;

TEST(ConversionsTest, EveryResultCodeKeepsItsName) {
  const std::pair<msg::ResultCode, const char*> codes[] = {
      {msg::OK, "OK"},
      {msg::INVALID_ARGUMENT, "INVALID_ARGUMENT"},
      {msg::UNKNOWN_HAND, "UNKNOWN_HAND"},
      {msg::TIMEOUT, "TIMEOUT"},
      {msg::BUS_DOWN, "BUS_DOWN"},
      {msg::BUSY, "BUSY"},
      {msg::NOT_INITIALIZED, "NOT_INITIALIZED"},
      {msg::DENIED, "DENIED"},
      {msg::CANCELLED, "CANCELLED"},
      {msg::FAILED, "FAILED"}};
  for (const auto& [wire, name] : codes) EXPECT_EQ(to_string(to_code(wire)), name);
}

TEST(ConversionsTest, AResultCodeFromANewerServiceIsAFailureNotSuccess) {
  EXPECT_EQ(to_code(static_cast<msg::ResultCode>(42)), Code::failed);
}

TEST(ConversionsTest, ReplyKeepsGraspOutcomeFinalPositionAndFoundIds) {
  msg::CommandReply wire;
  wire.command(msg::GRASP);
  wire.code(msg::OK);
  wire.grasp(msg::GRASPED);
  wire.value(37);
  wire.found_ids({1, 3});
  wire.lease_holder("abc");
  const Reply reply = to_reply(wire);
  EXPECT_TRUE(reply.ok());
  EXPECT_EQ(reply.grasp, GraspOutcome::grasped);
  EXPECT_EQ(reply.value, 37);
  EXPECT_EQ(reply.found_ids, (std::vector<std::uint16_t>{1, 3}));
  EXPECT_EQ(reply.lease_holder, "abc");
}

TEST(ConversionsTest, AnErrorReplyKeepsTheServicesMessage) {
  msg::CommandReply wire;
  wire.command(msg::MOVE);
  wire.code(msg::NOT_INITIALIZED);
  wire.message("hand 1 on bus 'bus0' is not initialized");
  const Reply reply = to_reply(wire);
  EXPECT_EQ(reply.code, Code::not_initialized);
  EXPECT_EQ(reply.message, "hand 1 on bus 'bus0' is not initialized");
}

TEST(ConversionsTest, AnErrorReplyWithoutMessageGetsOne) {
  msg::CommandReply wire;
  wire.command(msg::MOVE);
  wire.code(msg::BUSY);
  EXPECT_EQ(to_reply(wire).message, "MOVE failed with BUSY");
}

TEST(ConversionsTest, StatusAndEventCarryEveryField) {
  msg::HandStatus s;
  s.service("cell");
  s.bus("bus0");
  s.can_id(2);
  s.name("left");
  s.online(true);
  s.initialized(true);
  s.grip(msg::GRIP_GRASPED);
  s.position(41);
  s.rotation_state(msg::ROTATION_BLOCKED);
  s.last_error(msg::TIMEOUT);
  s.firmware_version_text("4.1.2.0");
  s.update_seq(9);
  const HandStatus status = to_public(s);
  EXPECT_EQ(status.address, (HandAddress{"cell", "bus0", 2}));
  EXPECT_EQ(status.name, "left");
  EXPECT_TRUE(status.online && status.initialized);
  EXPECT_EQ(status.grip, GripState::grasped);
  EXPECT_EQ(status.position, 41);
  EXPECT_EQ(status.rotation_state, RotationState::blocked);
  EXPECT_EQ(status.last_error, Code::timeout);
  EXPECT_EQ(status.firmware_version_text, "4.1.2.0");
  EXPECT_EQ(status.update_seq, 9U);
  EXPECT_FALSE(status.service_lost);

  msg::HandEvent e;
  e.hand().service("cell");
  e.hand().bus("bus0");
  e.hand().can_id(2);
  e.kind(msg::EVENT_DROPPED);
  e.position(55);
  e.position_known(true);
  e.event_seq(4);
  const HandEvent event = to_public(e);
  EXPECT_EQ(event.hand, (HandAddress{"cell", "bus0", 2}));
  EXPECT_EQ(event.kind, EventKind::dropped);
  EXPECT_EQ(event.position, 55);
  EXPECT_EQ(event.event_seq, 4U);
  EXPECT_FALSE(event.from_client);
  e.kind(msg::EVENT_GRASPED);
  e.position(-1);
  e.position_known(false);
  EXPECT_EQ(to_public(e).position, std::nullopt) << "not read yet is no number";
}

TEST(ConversionsTest, ServiceInfoListsBusesAndHands) {
  msg::ServiceInfo wire;
  wire.service("cell");
  wire.admin_allowed(true);
  msg::BusInfo bus;
  bus.name("bus0");
  bus.spec("sim:1,2");
  msg::HandInfo hand;
  hand.can_id(2);
  hand.name("right");
  bus.hands().push_back(hand);
  wire.buses().push_back(bus);
  const ServiceInfo info = to_public(wire);
  EXPECT_EQ(info.name, "cell");
  EXPECT_TRUE(info.admin_allowed);
  ASSERT_EQ(info.buses.size(), 1U);
  EXPECT_EQ(info.buses[0].spec, "sim:1,2");
  ASSERT_EQ(info.buses[0].hands.size(), 1U);
  EXPECT_EQ(info.buses[0].hands[0].name, "right");
}

msg::CommandRequest request(msg::CommandType command, std::int32_t value,
                            std::uint16_t can_id = 1) {
  msg::CommandRequest r;
  r.hand(to_msg(HandAddress{"cell", "bus0", can_id}));
  r.command(command);
  r.value(value);
  return r;
}

TEST(CheckRequestTest, ValuesInsideTheContractsLimitsPass) {
  EXPECT_TRUE(check_request(request(msg::MOVE, 0)).ok());
  EXPECT_TRUE(check_request(request(msg::MOVE, 100)).ok());
  EXPECT_TRUE(check_request(request(msg::GRASP, 20)).ok());
  EXPECT_TRUE(check_request(request(msg::SET_BAUD_RATE, 5)).ok());
  EXPECT_TRUE(check_request(request(msg::ACQUIRE_LEASE, 100)).ok());
  EXPECT_TRUE(check_request(request(msg::INITIALIZE, -7)).ok());  // value unused
  EXPECT_TRUE(check_request(request(msg::SCAN, 0, 0)).ok());      // a whole bus
}

TEST(CheckRequestTest, OutOfRangeValuesAreInvalidArgumentsNamingTheRange) {
  const auto move = check_request(request(msg::MOVE, 101));
  ASSERT_FALSE(move.ok());
  EXPECT_EQ(move.error().code, Code::invalid_argument);
  EXPECT_THAT(move.error().message, HasSubstr("MOVE value 101 is out of range"));
  EXPECT_THAT(move.error().message, HasSubstr("(0-100)"));
  EXPECT_THAT(check_request(request(msg::GRASP, 19)).error().message, HasSubstr("(20-100)"));
  EXPECT_THAT(check_request(request(msg::SET_CAN_ID, 256)).error().message, HasSubstr("(1-255)"));
  EXPECT_THAT(check_request(request(msg::SET_BAUD_RATE, 6)).error().message, HasSubstr("(0-5)"));
  EXPECT_THAT(check_request(request(msg::RENEW_LEASE, 99)).error().message, HasSubstr("lease"));
}

TEST(CheckRequestTest, AHandCommandNeedsAServiceABusAndACanId) {
  EXPECT_THAT(check_request(request(msg::MOVE, 50, 0)).error().message, HasSubstr("CAN ID"));
  auto no_bus = request(msg::MOVE, 50);
  no_bus.hand().bus("");
  EXPECT_THAT(check_request(no_bus).error().message, HasSubstr("bus"));
  auto no_service = request(msg::MOVE, 50);
  no_service.hand().service("");
  EXPECT_THAT(check_request(no_service).error().message, HasSubstr("service"));
}

}  // namespace
}  // namespace dh3::detail
