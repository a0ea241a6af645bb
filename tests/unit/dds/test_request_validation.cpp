#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>

#include "conversions.hpp"
#include "dh3/protocol/registers.hpp"
#include "request_validation.hpp"

namespace dh3::dds {
namespace {

using ::testing::HasSubstr;

class RequestValidationTest : public ::testing::Test {
 protected:
  RequestValidationTest() {
    directory_.add_bus("bus0", bus0_);
    directory_.add_bus("bus1", bus1_);
  }

  static msg::CommandRequest request(msg::CommandType command, std::int32_t value = 0,
                                     std::uint16_t can_id = 1, std::string bus = "bus0") {
    msg::CommandRequest r;
    r.client_id("0102030405060708090a0b0c");
    r.request_seq(7);
    r.hand().service("dh3");
    r.hand().bus(std::move(bus));
    r.hand().can_id(can_id);
    r.command(command);
    r.value(value);
    return r;
  }

  Result<ValidRequest, Rejection> check(const msg::CommandRequest& r, bool allow_admin = false) {
    return validate_request(r, directory_, allow_admin);
  }

  void expect_rejected(const msg::CommandRequest& r, msg::ResultCode code, const char* text,
                       bool allow_admin = false) {
    const auto result = check(r, allow_admin);
    ASSERT_FALSE(result.ok()) << "accepted " << command_name(r.command());
    EXPECT_EQ(result.error().code, code) << result.error().message;
    EXPECT_THAT(result.error().message, HasSubstr(text));
  }

  // The buses' rosters, which their schedulers own in the service.
  hand::HandRoster bus0_{{{1, "left"}, {2, "right"}, {3, ""}}};
  hand::HandRoster bus1_{{{5, ""}}};
  HandDirectory directory_;
};

TEST_F(RequestValidationTest, MoveInRangeBecomesAHandCommand) {
  const auto result = check(request(msg::MOVE, 60, 2));
  ASSERT_TRUE(result.ok()) << result.error().message;
  EXPECT_EQ(result->action, RequestAction::hand_command);
  EXPECT_EQ(result->bus, 0);
  EXPECT_EQ(result->can_id, 2);
  EXPECT_EQ(result->command.kind, hand::CommandKind::move_to);
  EXPECT_EQ(result->command.value, 60);
  EXPECT_FALSE(result->command.timeout);
  EXPECT_TRUE(result->needs_lease);
}

TEST_F(RequestValidationTest, EveryHandCommandMapsToItsKind) {
  struct Case {
    msg::CommandType command;
    std::int32_t value;
    hand::CommandKind kind;
  };
  const Case cases[] = {
      {msg::INITIALIZE, 0, hand::CommandKind::initialize},
      {msg::MOVE, 0, hand::CommandKind::move_to},
      {msg::SET_CLOSING_FORCE, 20, hand::CommandKind::set_closing_force},
      {msg::SET_OPENING_FORCE, 100, hand::CommandKind::set_opening_force},
      {msg::ROTATE, 100, hand::CommandKind::rotate_to},
      {msg::GRASP, 50, hand::CommandKind::grasp},
      {msg::RELEASE, 100, hand::CommandKind::release},
      {msg::STOP, 0, hand::CommandKind::stop},
  };
  for (const auto& c : cases) {
    const auto result = check(request(c.command, c.value));
    ASSERT_TRUE(result.ok()) << command_name(c.command) << ": " << result.error().message;
    EXPECT_EQ(result->command.kind, c.kind) << command_name(c.command);
    EXPECT_EQ(result->command.value, c.value) << command_name(c.command);
    EXPECT_TRUE(result->needs_lease) << command_name(c.command);
  }
}

TEST_F(RequestValidationTest, AdministrativeWritesTargetTheirRegisters) {
  auto id = check(request(msg::SET_CAN_ID, 9), true);
  ASSERT_TRUE(id.ok()) << id.error().message;
  EXPECT_EQ(id->command.kind, hand::CommandKind::write_register);
  EXPECT_EQ(id->command.reg, protocol::reg::kCanId);
  EXPECT_EQ(id->command.value, 9);
  auto baud = check(request(msg::SET_BAUD_RATE, 2), true);
  ASSERT_TRUE(baud.ok()) << baud.error().message;
  EXPECT_EQ(baud->command.reg, protocol::reg::kBaudRate);
  auto feedback = check(request(msg::ENABLE_INIT_FEEDBACK, 77));
  ASSERT_TRUE(feedback.ok()) << feedback.error().message;
  EXPECT_EQ(feedback->command.reg, protocol::reg::kInitFeedback);
  EXPECT_EQ(feedback->command.value, 0);  // the document enables it by writing 0
}

TEST_F(RequestValidationTest, ReadRegisterIsOpenToEveryone) {
  auto r = request(msg::READ_REGISTER);
  r.register_code(protocol::reg::kFirmwareVersion.code());
  const auto result = check(r);
  ASSERT_TRUE(result.ok()) << result.error().message;
  EXPECT_EQ(result->command.kind, hand::CommandKind::read_register);
  EXPECT_EQ(result->command.reg, protocol::reg::kFirmwareVersion);
  EXPECT_FALSE(result->needs_lease);
}

TEST_F(RequestValidationTest, UnknownRegisterIsInvalid) {
  auto r = request(msg::READ_REGISTER);
  r.register_code(0x0999);
  expect_rejected(r, msg::INVALID_ARGUMENT, "0x0999");
}

TEST_F(RequestValidationTest, TimeoutIsPassedOnAndBounded) {
  auto r = request(msg::MOVE, 10);
  r.timeout_ms(2500);
  const auto result = check(r);
  ASSERT_TRUE(result.ok());
  EXPECT_EQ(result->command.timeout, std::chrono::milliseconds(2500));
  r.timeout_ms(limits::REQUEST_TIMEOUT_MAX_MS + 1);
  expect_rejected(r, msg::INVALID_ARGUMENT, "timeout_ms");
}

TEST_F(RequestValidationTest, ValuesOutsideTheLimitsAreInvalid) {
  expect_rejected(request(msg::MOVE, 101), msg::INVALID_ARGUMENT, "101");
  expect_rejected(request(msg::MOVE, -1), msg::INVALID_ARGUMENT, "0-100");
  expect_rejected(request(msg::RELEASE, 150), msg::INVALID_ARGUMENT, "position");
  expect_rejected(request(msg::ROTATE, 101), msg::INVALID_ARGUMENT, "rotation");
  expect_rejected(request(msg::SET_CLOSING_FORCE, 19), msg::INVALID_ARGUMENT, "20-100");
  expect_rejected(request(msg::SET_OPENING_FORCE, 101), msg::INVALID_ARGUMENT, "force");
  expect_rejected(request(msg::GRASP, 10), msg::INVALID_ARGUMENT, "force");
  expect_rejected(request(msg::SET_CAN_ID, 256), msg::INVALID_ARGUMENT, "1-255", true);
  expect_rejected(request(msg::SET_CAN_ID, 0), msg::INVALID_ARGUMENT, "CAN ID", true);
  expect_rejected(request(msg::SET_BAUD_RATE, 6), msg::INVALID_ARGUMENT, "0-5", true);
  expect_rejected(request(msg::ACQUIRE_LEASE, 99), msg::INVALID_ARGUMENT, "lease");
  expect_rejected(request(msg::RENEW_LEASE, 600001), msg::INVALID_ARGUMENT, "lease");
}

TEST_F(RequestValidationTest, OutOfRangeWinsOverMissingAdminRight) {
  // Nothing malformed ever gets as far as the permission check.
  expect_rejected(request(msg::SET_CAN_ID, 300), msg::INVALID_ARGUMENT, "300");
}

TEST_F(RequestValidationTest, MalformedRequestsAreInvalid) {
  auto r = request(msg::MOVE, 10);
  r.client_id("");
  expect_rejected(r, msg::INVALID_ARGUMENT, "client_id");
  r.client_id(std::string(limits::MAX_NAME_LENGTH + 1, 'x'));
  expect_rejected(r, msg::INVALID_ARGUMENT, "client_id");
  r = request(msg::MOVE, 10);
  r.hand().service("");
  expect_rejected(r, msg::INVALID_ARGUMENT, "service");
  r = request(msg::MOVE, 10, 1, "");
  expect_rejected(r, msg::INVALID_ARGUMENT, "bus");
  r = request(static_cast<msg::CommandType>(99));
  expect_rejected(r, msg::INVALID_ARGUMENT, "unknown command 99");
}

TEST_F(RequestValidationTest, CanIdMustAddressOneHand) {
  expect_rejected(request(msg::MOVE, 10, 0), msg::INVALID_ARGUMENT, "can_id 0");
  expect_rejected(request(msg::MOVE, 10, 256), msg::INVALID_ARGUMENT, "can_id 256");
  expect_rejected(request(msg::ACQUIRE_LEASE, 1000, 0), msg::INVALID_ARGUMENT, "can_id 0");
}

TEST_F(RequestValidationTest, CanIdZeroIsForTheCanIdRegisterOnly) {
  auto read = request(msg::READ_REGISTER, 0, 0);
  read.register_code(protocol::reg::kCanId.code());
  const auto result = check(read);
  ASSERT_TRUE(result.ok()) << result.error().message;
  EXPECT_EQ(result->can_id, 0);
  EXPECT_TRUE(check(request(msg::SET_CAN_ID, 4, 0), true).ok());
  read.register_code(protocol::reg::kPosition.code());
  expect_rejected(read, msg::INVALID_ARGUMENT, "can_id 0");
}

TEST_F(RequestValidationTest, ScanIgnoresTheCanId) {
  for (const std::uint16_t id : {0, 1, 300}) {
    const auto result = check(request(msg::SCAN, 0, id, "bus1"));
    ASSERT_TRUE(result.ok()) << result.error().message;
    EXPECT_EQ(result->action, RequestAction::scan);
    EXPECT_EQ(result->bus, 1);
    EXPECT_FALSE(result->needs_lease);
  }
}

TEST_F(RequestValidationTest, UnknownBusOrHandIsUnknownHand) {
  expect_rejected(request(msg::MOVE, 10, 1, "bus7"), msg::UNKNOWN_HAND, "bus0, bus1");
  expect_rejected(request(msg::MOVE, 10, 4), msg::UNKNOWN_HAND, "no hand 4");
  expect_rejected(request(msg::SCAN, 0, 0, "nope"), msg::UNKNOWN_HAND, "nope");
  expect_rejected(request(msg::ACQUIRE_LEASE, 1000, 5), msg::UNKNOWN_HAND, "no hand 5");
}

TEST_F(RequestValidationTest, DiscoveredHandsBecomeKnown) {
  expect_rejected(request(msg::MOVE, 10, 7, "bus1"), msg::UNKNOWN_HAND, "no hand 7");
  EXPECT_TRUE(bus1_.add(7));  // as bus1's scheduler does when hand 7 answers a probe
  EXPECT_FALSE(bus1_.add(7));
  EXPECT_TRUE(check(request(msg::MOVE, 10, 7, "bus1")).ok());
}

TEST_F(RequestValidationTest, AdministrativeCommandsNeedTheServicesPermission) {
  expect_rejected(request(msg::SET_CAN_ID, 2), msg::DENIED, "--allow-admin");
  expect_rejected(request(msg::SET_BAUD_RATE, 2), msg::DENIED, "administrative");
  EXPECT_TRUE(check(request(msg::SET_BAUD_RATE, 2), true).ok());
}

TEST_F(RequestValidationTest, LeaseRequestsCarryTheirTimeToLive) {
  const auto acquire = check(request(msg::ACQUIRE_LEASE, 1500));
  ASSERT_TRUE(acquire.ok());
  EXPECT_EQ(acquire->action, RequestAction::acquire_lease);
  EXPECT_EQ(acquire->lease_ttl, std::chrono::milliseconds(1500));
  EXPECT_EQ(check(request(msg::RENEW_LEASE, 100))->action, RequestAction::renew_lease);
  // A release needs no time to live.
  EXPECT_EQ(check(request(msg::RELEASE_LEASE, -5))->action, RequestAction::release_lease);
}

}  // namespace
}  // namespace dh3::dds
