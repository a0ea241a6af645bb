#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>

#include "app/config.hpp"

namespace dh3::app {
namespace {

using std::chrono::milliseconds;
using ::testing::HasSubstr;

ServiceConfig parse_ok(const char* yaml) {
  auto result = parse_config(yaml, "cell.yaml");
  EXPECT_TRUE(result.ok()) << result.error().message;
  return result.ok() ? std::move(*result) : ServiceConfig{};
}

std::string parse_error(const char* yaml) {
  auto result = parse_config(yaml, "cell.yaml");
  EXPECT_FALSE(result.ok()) << "accepted:\n" << yaml;
  return result.ok() ? std::string{} : result.error().message;
}

TEST(Config, DefaultRunsThreeSimulatedHands) {
  const auto config = default_config();
  EXPECT_EQ(config.name, "dh3");
  EXPECT_EQ(config.domain, 0);
  EXPECT_FALSE(config.allow_admin);
  EXPECT_TRUE(config.interfaces.empty());  // loopback only
  ASSERT_EQ(config.buses.size(), 1U);
  EXPECT_EQ(config.buses[0].spec, "sim:1,2,3");
  ASSERT_EQ(config.buses[0].hands.size(), 3U);
  EXPECT_EQ(config.buses[0].hands[2].id, 3);
  // The simulator should feel real: replies take a moment.
  EXPECT_GT(config.buses[0].sim.reply_delay, Duration::zero());
}

TEST(Config, FullFileIsRead) {
  const auto config = parse_ok(R"(
name: cell7
domain: 42
log_level: debug
allow_admin: true
dds:
  interfaces: [127.0.0.1, 10.0.0.5]
  udp_only: true
buses:
  - name: left
    spec: tcp:127.0.0.1:9000
    command_interval_ms: 5
    poll_interval_moving_ms: 30
    poll_interval_idle_ms: 400
    reply_timeout_ms: 100
    admin_reply_timeout_ms: 4000
    max_retries: 1
    offline_after_timeouts: 2
    offline_probe_interval_ms: 700
    init_timeout_ms: 9000
    motion_timeout_ms: 8000
    queue_capacity: 4
    discovery_interval_ms: 0
    probe_spacing_ms: 3
    hands:
      - {id: 1, name: gripper}
      - id: 2
  - spec: sim
    sim: {reply_delay_ms: 0, position_speed: 1000, rotation_speed: 500, init_time_ms: 50, bit_rate: 1000000}
    hands:
      - {id: 4, object: 40, rotation_obstacle: 70}
)");
  EXPECT_EQ(config.name, "cell7");
  EXPECT_EQ(config.domain, 42);
  EXPECT_EQ(config.log_level, "debug");
  EXPECT_TRUE(config.allow_admin);
  EXPECT_THAT(config.interfaces, ::testing::ElementsAre("127.0.0.1", "10.0.0.5"));
  EXPECT_TRUE(config.udp_only);
  ASSERT_EQ(config.buses.size(), 2U);
  const auto& left = config.buses[0];
  EXPECT_EQ(left.name, "left");
  EXPECT_EQ(left.spec, "tcp:127.0.0.1:9000");
  EXPECT_EQ(left.scheduler.command_interval, milliseconds(5));
  EXPECT_EQ(left.scheduler.poll_interval_moving, milliseconds(30));
  EXPECT_EQ(left.scheduler.poll_interval_idle, milliseconds(400));
  EXPECT_EQ(left.scheduler.reply_timeout, milliseconds(100));
  EXPECT_EQ(left.scheduler.admin_reply_timeout, milliseconds(4000));
  EXPECT_EQ(left.scheduler.max_retries, 1);
  EXPECT_EQ(left.scheduler.offline_after_timeouts, 2);
  EXPECT_EQ(left.scheduler.offline_probe_interval, milliseconds(700));
  EXPECT_EQ(left.scheduler.init_timeout, milliseconds(9000));
  EXPECT_EQ(left.scheduler.motion_timeout, milliseconds(8000));
  EXPECT_EQ(left.scheduler.queue_capacity, 4U);
  EXPECT_EQ(left.scheduler.discovery_interval, Duration::zero());
  EXPECT_EQ(left.scheduler.probe_spacing, milliseconds(3));
  ASSERT_EQ(left.hands.size(), 2U);
  EXPECT_EQ(left.hands[0].name, "gripper");
  EXPECT_EQ(left.hands[1].id, 2);
  const auto& sim = config.buses[1];
  EXPECT_EQ(sim.name, "bus1");  // named by position when the file does not name it
  EXPECT_EQ(sim.sim.reply_delay, Duration::zero());
  EXPECT_DOUBLE_EQ(sim.sim.position_speed, 1000.0);
  EXPECT_DOUBLE_EQ(sim.sim.rotation_speed, 500.0);
  EXPECT_EQ(sim.sim.init_time, milliseconds(50));
  EXPECT_EQ(sim.sim.bit_rate, 1000000U);
  ASSERT_EQ(sim.hands.size(), 1U);
  EXPECT_EQ(sim.hands[0].object, 40);
  EXPECT_EQ(sim.hands[0].rotation_obstacle, 70);
}

TEST(Config, EmptyFileKeepsDefaultsButHasNoBus) {
  const auto config = parse_ok("");
  EXPECT_EQ(config.name, "dh3");
  EXPECT_TRUE(config.buses.empty());
  const auto applied = apply_command_line(config, CommandLine{});
  ASSERT_FALSE(applied.ok());
  EXPECT_THAT(applied.error().message, HasSubstr("no bus"));
}

TEST(Config, ErrorsNameTheKeyAndTheLine) {
  EXPECT_EQ(parse_error("name: dh3\ndomain: 300\n"),
            "cell.yaml:2: domain: 300 is out of range (0-232)");
  EXPECT_EQ(parse_error("domain: zero\n"), "cell.yaml:1: domain: 'zero' is not an integer");
  EXPECT_THAT(parse_error("buses:\n  - spec: sim\n    hands:\n      - id: 1\n      - id: 300\n"),
              HasSubstr("cell.yaml:5: buses[0].hands[1].id: 300 is out of range (1-255)"));
  EXPECT_THAT(parse_error("buses:\n  - spec: tcp:box\n"), HasSubstr("cell.yaml:2: buses[0].spec:"));
  EXPECT_THAT(parse_error("buses:\n  - name: a\n"),
              HasSubstr("cell.yaml:2: buses[0].spec: missing"));
  EXPECT_THAT(parse_error("buses:\n  - spec: sim\n    comand_interval_ms: 5\n"),
              HasSubstr("cell.yaml:3: buses[0].comand_interval_ms: unknown key"));
  EXPECT_THAT(parse_error("nmae: x\n"), HasSubstr("cell.yaml:1: nmae: unknown key"));
  EXPECT_THAT(parse_error("log_level: loud\n"), HasSubstr("cell.yaml:1: log_level:"));
  EXPECT_THAT(parse_error("allow_admin: maybe\n"), HasSubstr("not true or false"));
  EXPECT_THAT(parse_error("dds:\n  interfaces: [300.1.1.1]\n"),
              HasSubstr("cell.yaml:2: dds.interfaces[0]: interface '300.1.1.1'"));
  EXPECT_THAT(parse_error("dds:\n  interfaces: ['*', 127.0.0.1]\n"),
              HasSubstr("cannot be combined"));
  EXPECT_THAT(parse_error("name: ''\n"), HasSubstr("cell.yaml:1: name: service name is empty"));
}

TEST(Config, SyntaxErrorsGiveTheLine) {
  EXPECT_THAT(parse_error("name: dh3\nbuses: [\n"), HasSubstr("cell.yaml:"));
  EXPECT_THAT(parse_error("name: dh3\n  bad: indent: here\n"), HasSubstr("cell.yaml:2"));
}

TEST(Config, DuplicatesAreRefused) {
  EXPECT_THAT(parse_error("buses:\n  - {name: a, spec: sim}\n  - {name: a, spec: sim}\n"),
              HasSubstr("cell.yaml:3: buses[1].name: bus name 'a' is used twice"));
  EXPECT_THAT(parse_error("buses:\n  - spec: sim\n    hands: [{id: 2}, {id: 2}]\n"),
              HasSubstr("CAN ID 2 is listed twice"));
}

TEST(Config, SimulatorSettingsOnlyOnSimBuses) {
  EXPECT_THAT(parse_error("buses:\n  - spec: tcp:127.0.0.1:9\n    hands: [{id: 1, object: 40}]\n"),
              HasSubstr("buses[0].hands[0].object: only simulated hands"));
  EXPECT_THAT(parse_error("buses:\n  - spec: tcp:127.0.0.1:9\n    sim: {reply_delay_ms: 1}\n"),
              HasSubstr("buses[0].sim: only a sim bus"));
  EXPECT_THAT(parse_error("buses:\n  - spec: sim\n    hands: [{id: 1, object: 140}]\n"),
              HasSubstr("out of range (0-100)"));
}

TEST(Config, CommandLineOverridesTheFile) {
  CommandLine line;
  line.name = "other";
  line.domain = 17;
  line.log_level = "warn";
  line.allow_admin = true;
  line.udp_only = true;
  line.interfaces = {"*"};
  line.buses = {"sim:4,5", "right=tcp:127.0.0.1:9000", "socketcan:can1"};
  auto config = apply_command_line(default_config(), line);
  ASSERT_TRUE(config.ok()) << config.error().message;
  EXPECT_EQ(config->name, "other");
  EXPECT_EQ(config->domain, 17);
  EXPECT_EQ(config->log_level, "warn");
  EXPECT_TRUE(config->allow_admin);
  EXPECT_TRUE(config->udp_only);
  EXPECT_THAT(config->interfaces, ::testing::ElementsAre("*"));
  ASSERT_EQ(config->buses.size(), 3U);  // --bus replaces the default sim bus
  EXPECT_EQ(config->buses[0].name, "bus0");
  EXPECT_EQ(config->buses[0].spec, "sim:4,5");
  EXPECT_EQ(config->buses[1].name, "right");
  EXPECT_EQ(config->buses[1].spec, "tcp:127.0.0.1:9000");
  EXPECT_EQ(config->buses[2].name, "can1");  // derived from the interface
}

TEST(Config, BadCommandLineValuesNameTheOption) {
  const auto error = [](CommandLine line) {
    auto config = apply_command_line(default_config(), line);
    EXPECT_FALSE(config.ok());
    return config.ok() ? std::string{} : config.error().message;
  };
  CommandLine line;
  line.domain = 233;
  EXPECT_THAT(error(line), HasSubstr("--domain"));
  line = {};
  line.buses = {"tcp:box"};
  EXPECT_THAT(error(line), HasSubstr("--bus tcp:box"));
  line = {};
  line.buses = {"a=sim", "a=sim:2"};
  EXPECT_THAT(error(line), HasSubstr("used twice"));
  line = {};
  line.interfaces = {"eth0"};
  EXPECT_THAT(error(line), HasSubstr("--interface"));
  line = {};
  line.log_level = "verbose";
  EXPECT_THAT(error(line), HasSubstr("--log-level"));
  line = {};
  line.name = std::string(65, 'n');
  EXPECT_THAT(error(line), HasSubstr("--name"));
}

TEST(Config, BusNamesDefaultByPosition) {
  EXPECT_EQ(default_bus_name("sim", 0), "bus0");
  EXPECT_EQ(default_bus_name("tcp:127.0.0.1:9000", 3), "bus3");
  EXPECT_EQ(default_bus_name("socketcan:can0", 1), "can0");
}

}  // namespace
}  // namespace dh3::app
