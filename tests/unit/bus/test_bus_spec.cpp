// Bus specs as users type them, and open_bus() creating the matching backend.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "dh3/bus/bus_spec.hpp"
#include "dh3/protocol/codec.hpp"
#include "support/bus_wait.hpp"

namespace dh3::bus {
namespace {

using ::testing::HasSubstr;

BusSpec parse_ok(std::string_view text) {
  auto parsed = parse_bus_spec(text);
  EXPECT_TRUE(parsed.ok()) << text << ": " << (parsed.ok() ? "" : parsed.error());
  return parsed.ok() ? parsed.value() : BusSpec{};
}

std::string parse_error(std::string_view text) {
  auto parsed = parse_bus_spec(text);
  EXPECT_FALSE(parsed.ok()) << text << " parsed but should not";
  return parsed.ok() ? std::string() : parsed.error();
}

TEST(BusSpec, PlainSimIsOneHandWithTheDefaultId) {
  const BusSpec spec = parse_ok("sim");
  EXPECT_EQ(spec.kind, BusKind::sim);
  EXPECT_EQ(spec.sim_hand_ids, (std::vector<std::uint8_t>{1}));
}

TEST(BusSpec, SimWithIdsKeepsThemInOrder) {
  EXPECT_EQ(parse_ok("sim:1,2,3").sim_hand_ids, (std::vector<std::uint8_t>{1, 2, 3}));
  EXPECT_EQ(parse_ok("sim:255,7").sim_hand_ids, (std::vector<std::uint8_t>{255, 7}));
  EXPECT_EQ(parse_ok("sim:1-3,7").sim_hand_ids, (std::vector<std::uint8_t>{1, 2, 3, 7}));
}

TEST(BusSpec, BadSimIdsAreRejectedWithTheReason) {
  EXPECT_THAT(parse_error("sim:"), HasSubstr("no hand ids"));
  EXPECT_THAT(parse_error("sim:0"), HasSubstr("hand id 0"));
  EXPECT_THAT(parse_error("sim:256"), HasSubstr("out of range 1-255"));
  EXPECT_THAT(parse_error("sim:1,,2"), HasSubstr("hand id '' is not a number"));
  EXPECT_THAT(parse_error("sim:1,x"), HasSubstr("hand id 'x' is not a number"));
  EXPECT_THAT(parse_error("sim:-1"), HasSubstr("'-1' is not a number"));
  EXPECT_THAT(parse_error("sim:1,2,1"), HasSubstr("hand id 1 is listed twice"));
  EXPECT_THAT(parse_error("sim:1 "), HasSubstr("'1 ' is not a number"));
  EXPECT_THAT(parse_error("sim:1-3,2"), HasSubstr("hand id 2 is listed twice"));
}

TEST(BusSpec, OnlySimSpecsAreSimulatedInProcess) {
  EXPECT_TRUE(is_simulated("sim"));
  EXPECT_TRUE(is_simulated("sim:1-4,7"));
  EXPECT_FALSE(is_simulated("socketcan:can0"));
  EXPECT_FALSE(is_simulated("tcp:box:9000"));
  EXPECT_FALSE(is_simulated("serial:/dev/ttyUSB0"));
  EXPECT_FALSE(is_simulated("sim:0"));  // a bad spec names no bus at all
}

TEST(BusSpec, SocketCanNamesAnInterface) {
  const BusSpec spec = parse_ok("socketcan:can0");
  EXPECT_EQ(spec.kind, BusKind::socketcan);
  EXPECT_EQ(spec.interface, "can0");
  EXPECT_EQ(parse_ok("socketcan:vcan-test.1").interface, "vcan-test.1");
}

TEST(BusSpec, BadSocketCanInterfacesAreRejected) {
  EXPECT_THAT(parse_error("socketcan"), HasSubstr("needs an argument"));
  EXPECT_THAT(parse_error("socketcan:"), HasSubstr("missing interface name"));
  EXPECT_THAT(parse_error("socketcan:a_name_of_16chars"), HasSubstr("longer than 15 characters"));
  EXPECT_THAT(parse_error("socketcan:can/0"), HasSubstr("not a valid interface name"));
  EXPECT_THAT(parse_error("socketcan:.."), HasSubstr("not a valid interface name"));
}

TEST(BusSpec, TcpTakesHostAndPort) {
  BusSpec spec = parse_ok("tcp:127.0.0.1:9000");
  EXPECT_EQ(spec.kind, BusKind::tcp);
  EXPECT_EQ(spec.host, "127.0.0.1");
  EXPECT_EQ(spec.port, 9000);
  spec = parse_ok("tcp:box.local:8888");
  EXPECT_EQ(spec.host, "box.local");
  EXPECT_EQ(spec.port, 8888);
  spec = parse_ok("tcp:[::1]:65535");
  EXPECT_EQ(spec.host, "::1");
  EXPECT_EQ(spec.port, 65535);
}

TEST(BusSpec, BadTcpSpecsSayWhatIsMissing) {
  EXPECT_THAT(parse_error("tcp"), HasSubstr("needs an argument"));
  EXPECT_THAT(parse_error("tcp:box"), HasSubstr("missing port"));
  EXPECT_THAT(parse_error("tcp:box:"), HasSubstr("missing port"));
  EXPECT_THAT(parse_error("tcp::9000"), HasSubstr("missing host"));
  EXPECT_THAT(parse_error("tcp:box:0"), HasSubstr("out of range 1-65535"));
  EXPECT_THAT(parse_error("tcp:box:65536"), HasSubstr("out of range 1-65535"));
  EXPECT_THAT(parse_error("tcp:box:90a"), HasSubstr("port '90a' is not a number"));
  EXPECT_THAT(parse_error("tcp:::1:9000"), HasSubstr("must be in brackets"));
  EXPECT_THAT(parse_error("tcp:[::1:9000"), HasSubstr("missing ']'"));
  EXPECT_THAT(parse_error("tcp:[::1]9000"), HasSubstr("missing port"));
  EXPECT_THAT(parse_error("tcp:box"), HasSubstr("expected tcp:HOST:PORT"));
}

TEST(BusSpec, SerialTakesDeviceAndBaudRate) {
  BusSpec spec = parse_ok("serial:/dev/ttyUSB0@115200");
  EXPECT_EQ(spec.kind, BusKind::serial);
  EXPECT_EQ(spec.device, "/dev/ttyUSB0");
  EXPECT_EQ(spec.baud_rate, 115200u);
  EXPECT_EQ(parse_ok("serial:/dev/ttyS1@9600").baud_rate, 9600u);
  EXPECT_EQ(parse_ok("serial:/dev/ttyS1@921600").baud_rate, 921600u);
  spec = parse_ok("serial:/dev/serial/by-id/usb-box");
  EXPECT_EQ(spec.device, "/dev/serial/by-id/usb-box");
  EXPECT_EQ(spec.baud_rate, kDefaultSerialBaudRate);
}

TEST(BusSpec, BadSerialSpecsAreRejected) {
  EXPECT_THAT(parse_error("serial:"), HasSubstr("missing device path"));
  EXPECT_THAT(parse_error("serial:@9600"), HasSubstr("missing device path"));
  EXPECT_THAT(parse_error("serial:/dev/ttyUSB0@fast"),
              HasSubstr("baud rate 'fast' is not a number"));
  EXPECT_THAT(parse_error("serial:/dev/ttyUSB0@"), HasSubstr("baud rate '' is not a number"));
  const std::string unsupported = parse_error("serial:/dev/ttyUSB0@12345");
  EXPECT_THAT(unsupported, HasSubstr("unsupported baud rate 12345"));
  EXPECT_THAT(unsupported, HasSubstr("115200"));  // the message lists what would work
}

TEST(BusSpec, UnknownOrEmptySpecsListTheKnownKinds) {
  EXPECT_THAT(parse_error(""), HasSubstr("empty bus spec"));
  const std::string unknown = parse_error("can:can0");
  EXPECT_THAT(unknown, HasSubstr("unknown bus type 'can'"));
  EXPECT_THAT(unknown, HasSubstr("socketcan:IFACE"));
  EXPECT_THAT(parse_error("Sim"), HasSubstr("unknown bus type 'Sim'"));
}

TEST(BusSpec, CanonicalTextParsesBackToTheSameSpec) {
  for (const char* text : {"sim:1,2,3", "socketcan:can0", "tcp:10.0.0.5:8888", "tcp:[fe80::1]:80",
                           "serial:/dev/ttyUSB0@115200"}) {
    const BusSpec spec = parse_ok(text);
    EXPECT_EQ(to_string(spec), text);
    EXPECT_EQ(parse_ok(to_string(spec)), spec);
  }
  EXPECT_EQ(to_string(parse_ok("sim")), "sim:1");
  EXPECT_EQ(to_string(parse_ok("serial:/dev/ttyS0")), "serial:/dev/ttyS0@115200");
}

TEST(OpenBus, BadSpecFailsWithTheParseMessage) {
  auto opened = open_bus("tcp:box", SystemClock::instance());
  ASSERT_FALSE(opened.ok());
  EXPECT_THAT(opened.error(), HasSubstr("missing port"));
}

TEST(OpenBus, SimSpecIsLeftToTheSimLayer) {
  // The bus layer knows no simulator; dh3-service's app layer makes a SimBus
  // for a sim spec (tests/unit/app/test_bus_setup.cpp).
  auto opened = open_bus("sim:2,5", SystemClock::instance());
  ASSERT_FALSE(opened.ok());
  EXPECT_THAT(opened.error(), HasSubstr("sim:2,5"));
}

TEST(OpenBus, TcpAndSerialSpecsCreateTransferBoxBuses) {
  // Nothing listens on these: the bus exists, is down and keeps retrying.
  OpenBusOptions options;
  options.transfer_box.reconnect.initial_backoff = std::chrono::seconds(60);
  auto tcp = open_bus("tcp:127.0.0.1:1", SystemClock::instance(), options);
  ASSERT_TRUE(tcp.ok()) << tcp.error();
  EXPECT_NE(dynamic_cast<TransferBoxBus*>(tcp.value().get()), nullptr);
  EXPECT_EQ(tcp.value()->spec(), "tcp:127.0.0.1:1");
  EXPECT_TRUE(test::wait_for_link(*tcp.value(), LinkState::down));

  auto serial = open_bus("serial:/nonexistent/ttyDH3@9600", SystemClock::instance(), options);
  ASSERT_TRUE(serial.ok()) << serial.error();
  EXPECT_NE(dynamic_cast<TransferBoxBus*>(serial.value().get()), nullptr);
  EXPECT_EQ(serial.value()->link_state(), LinkState::down);
  std::vector<CanFrame> frames;
  auto received = serial.value()->receive(frames, std::chrono::milliseconds(1));
  ASSERT_FALSE(received.ok());
  EXPECT_EQ(received.error(), BusError::link_down);
}

TEST(OpenBus, SocketCanWithoutKernelSupportIsAClearError) {
  const std::string problem = kernel_can_support_problem();
  auto opened = open_bus("socketcan:dh3nocan0", SystemClock::instance());
  if (problem.empty()) {
    // This kernel has CAN: a missing interface gives a bus that waits for it.
    ASSERT_TRUE(opened.ok()) << opened.error();
    EXPECT_EQ(opened.value()->link_state(), LinkState::down);
    return;
  }
  ASSERT_FALSE(opened.ok());
  EXPECT_THAT(opened.error(), HasSubstr("socketcan:dh3nocan0"));
  EXPECT_THAT(opened.error(), HasSubstr("kernel has no CAN support"));
  EXPECT_THAT(opened.error(), HasSubstr("socket(PF_CAN)"));
}

TEST(BusErrorText, NamesEveryError) {
  EXPECT_EQ(to_string(BusError::link_down), "link_down");
  EXPECT_EQ(to_string(BusError::io_error), "io_error");
  EXPECT_EQ(to_string(BusError::frame_invalid), "frame_invalid");
  EXPECT_EQ(to_string(BusError::would_block), "would_block");
}

}  // namespace
}  // namespace dh3::bus
