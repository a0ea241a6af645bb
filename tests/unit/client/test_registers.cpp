// Register names and codes for `dh3ctl read`, the firmware version text, and
// the names of the public enums as dh3ctl prints them.

#include <gtest/gtest.h>

#include <string>

#include "dh3/registers.hpp"
#include "dh3/types.hpp"

namespace dh3 {
namespace {

TEST(RegistersTest, NamesAndCodesBothWork) {
  EXPECT_EQ(parse_register("position"), reg::position);
  EXPECT_EQ(parse_register("grip-status"), reg::grip_status);
  EXPECT_EQ(parse_register("Firmware_Version"), reg::firmware_version);
  EXPECT_EQ(parse_register("0x0602"), 0x0602);
  EXPECT_EQ(parse_register("0X1301"), 0x1301);
  EXPECT_EQ(parse_register("1538"), 1538);
  EXPECT_EQ(register_name(0x0602), "position");
  EXPECT_EQ(register_name(0x9999), "");
}

TEST(RegistersTest, GarbageIsNotARegister) {
  for (const char* text : {"", "0x", "posit", "0x10000", "12ab", "-1"}) {
    EXPECT_FALSE(parse_register(text)) << text;
  }
}

TEST(RegistersTest, FirmwareVersionReadsBytesHighToLow) {
  // The document's 00 02 01 04, little-endian 0x04010200.
  EXPECT_EQ(firmware_version_text(0x04010200), "4.1.2.0");
  EXPECT_EQ(firmware_version_text(-1), "255.255.255.255");
}

TEST(TypesTest, CodesReadAsTheWireSpellsThem) {
  EXPECT_EQ(to_string(Code::ok), "OK");
  EXPECT_EQ(to_string(Code::not_initialized), "NOT_INITIALIZED");
  EXPECT_EQ(to_string(Code::service_lost), "SERVICE_LOST");
  EXPECT_EQ(to_string(GraspOutcome::missed), "MISSED");
  EXPECT_EQ(to_string(GripState::missed), "MISSED");
  EXPECT_EQ(to_string(EventKind::rotation_blocked), "ROTATION_BLOCKED");
  EXPECT_EQ(to_string(EventKind::taken_over), "TAKEN_OVER");
}

TEST(TypesTest, ReplyIsTrueOnlyWhenOk) {
  Reply reply;
  EXPECT_TRUE(reply);
  reply.code = Code::cancelled;
  EXPECT_FALSE(reply);
  EXPECT_FALSE(reply.ok());
}

TEST(TypesTest, AnEventsValueIsNamedWhereItMeansSomething) {
  HandEvent event;
  event.value = 7;
  const auto name_for = [&event](EventKind kind) {
    event.kind = kind;
    const auto named = named_value(event);
    return named ? std::string(named->name) + "=" + std::to_string(named->value) : "-";
  };
  EXPECT_EQ(name_for(EventKind::grasped), "closing_force=7");
  EXPECT_EQ(name_for(EventKind::arrived), "grip_status=7");
  EXPECT_EQ(name_for(EventKind::missed), "grip_status=7");
  EXPECT_EQ(name_for(EventKind::dropped), "grip_status=7");
  EXPECT_EQ(name_for(EventKind::rotation_arrived), "rotation_status=7");
  EXPECT_EQ(name_for(EventKind::rotation_blocked), "rotation_status=7");
  EXPECT_EQ(name_for(EventKind::online), "firmware_version=7");
  EXPECT_EQ(name_for(EventKind::offline), "unanswered_requests=7");
  for (const EventKind kind :
       {EventKind::initialized, EventKind::init_failed, EventKind::fault, EventKind::taken_over}) {
    EXPECT_EQ(name_for(kind), "-") << to_string(kind);
  }
}

}  // namespace
}  // namespace dh3
