#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "dh3/app/config.hpp"

namespace dh3::app {
namespace {

using std::chrono::milliseconds;
using ::testing::AllOf;
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
  EXPECT_EQ(config.participant.domain, 0);
  EXPECT_FALSE(config.allow_admin);
  EXPECT_TRUE(config.participant.interfaces.empty());  // loopback only
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
    interval_margin_ms: 1
    poll_interval_watch_ms: 25
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
  EXPECT_EQ(config.participant.domain, 42);
  EXPECT_EQ(config.log_level, "debug");
  EXPECT_TRUE(config.allow_admin);
  EXPECT_THAT(config.participant.interfaces, ::testing::ElementsAre("127.0.0.1", "10.0.0.5"));
  EXPECT_TRUE(config.participant.udp_only);
  ASSERT_EQ(config.buses.size(), 2U);
  const auto& left = config.buses[0];
  EXPECT_EQ(left.name, "left");
  EXPECT_EQ(left.spec, "tcp:127.0.0.1:9000");
  EXPECT_EQ(left.scheduler.command_interval, milliseconds(5));
  EXPECT_EQ(left.interval_margin, milliseconds(1));
  EXPECT_EQ(left.scheduler.poll_interval_watch, milliseconds(25));
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
  EXPECT_FALSE(sim.interval_margin.has_value());  // the bus kind's default (bus_setup)
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

// A hand at rest republished every 5 s unless the file says otherwise.
TEST(Config, StatusRefreshIsFiveSecondsUnlessTheFileSays) {
  EXPECT_EQ(default_config().status_refresh, std::chrono::seconds(5));
  auto from_file =
      parse_config("dds:\n  status_refresh_ms: 250\nbuses:\n  - spec: sim\n", "cell.yaml");
  ASSERT_TRUE(from_file.ok()) << from_file.error().message;
  EXPECT_EQ(from_file->status_refresh, std::chrono::milliseconds(250));
  EXPECT_THAT(parse_error("dds:\n  status_refresh_ms: -1\nbuses:\n  - spec: sim\n"),
              HasSubstr("dds.status_refresh_ms"));
}

// UDP alone unless shared memory is asked for: the file's choice,
// and the command line's over it.
TEST(Config, SharedMemoryIsOffUnlessAskedForAndTheCommandLineDecides) {
  EXPECT_FALSE(default_config().participant.shared_memory);
  auto from_file =
      parse_config("dds:\n  shared_memory: true\nbuses:\n  - spec: sim\n", "cell.yaml");
  ASSERT_TRUE(from_file.ok()) << from_file.error().message;
  EXPECT_TRUE(from_file->participant.shared_memory);

  CommandLine udp;
  udp.udp_only = true;
  auto overridden = apply_command_line(*from_file, udp);
  ASSERT_TRUE(overridden.ok()) << overridden.error().message;
  EXPECT_FALSE(overridden->participant.shared_memory);
  EXPECT_TRUE(overridden->participant.udp_only);

  CommandLine shm;
  shm.shared_memory = true;
  auto asked = apply_command_line(default_config(), shm);
  ASSERT_TRUE(asked.ok()) << asked.error().message;
  EXPECT_TRUE(asked->participant.shared_memory);

  CommandLine both;
  both.udp_only = true;
  both.shared_memory = true;
  auto refused = apply_command_line(default_config(), both);
  ASSERT_FALSE(refused.ok());
  EXPECT_THAT(refused.error().message,
              AllOf(HasSubstr("--shared-memory"), HasSubstr("contradicts --udp-only")));
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
  EXPECT_EQ(config->participant.domain, 17);
  EXPECT_EQ(config->log_level, "warn");
  EXPECT_TRUE(config->allow_admin);
  EXPECT_TRUE(config->participant.udp_only);
  EXPECT_THAT(config->participant.interfaces, ::testing::ElementsAre("*"));
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

/// A directory laid out as deploy/security/make-test-pki.sh writes it (the
/// files' content does not matter to the configuration, only that they exist).
class SecurityDir {
 public:
  explicit SecurityDir(const std::string& identity) {
    char pattern[] = "/tmp/dh3-config-test-XXXXXX";
    dir_ = ::mkdtemp(pattern);
    std::filesystem::create_directories(dir_ / identity);
    for (const char* file : {"identity_ca.pem", "permissions_ca.pem", "governance.p7s"}) {
      std::ofstream(dir_ / file) << "x";
    }
    for (const char* file : {"cert.pem", "key.pem", "permissions.p7s"}) {
      std::ofstream(dir_ / identity / file) << "x";
    }
    std::ofstream(dir_ / "profiles.xml") << "<dds/>";
  }
  ~SecurityDir() { std::filesystem::remove_all(dir_); }
  SecurityDir(const SecurityDir&) = delete;
  SecurityDir& operator=(const SecurityDir&) = delete;
  [[nodiscard]] std::string path() const { return dir_.string(); }
  [[nodiscard]] std::string xml() const { return (dir_ / "profiles.xml").string(); }
  void remove(const std::string& relative) const { std::filesystem::remove(dir_ / relative); }

 private:
  std::filesystem::path dir_;
};

TEST(Config, DiscoveryServersXmlProfileAndSecurityAreRead) {
  const SecurityDir pki("operator");
  const std::string yaml =
      "dds:\n"
      "  discovery_servers: [127.0.0.1:11811, ~, 10.0.0.2]\n"
      "  xml_profile_file: " +
      pki.xml() +
      "\n"
      "  xml_profile: dh3_udp\n"
      "  security: {dir: " +
      pki.path() + ", identity: operator}\n";
  auto config = parse_config(yaml, "cell.yaml");
  ASSERT_TRUE(config.ok()) << config.error().message;
  // The empty entry keeps its place: the third entry is server id 2.
  EXPECT_THAT(config->participant.discovery_servers,
              ::testing::ElementsAre("127.0.0.1:11811", "", "10.0.0.2"));
  EXPECT_EQ(config->participant.xml_profile_file, pki.xml());
  EXPECT_EQ(config->participant.xml_profile, "dh3_udp");
  EXPECT_EQ(config->participant.security_dir, pki.path());
  EXPECT_EQ(config->participant.security_identity, "operator");
}

TEST(Config, SecurityIdentityDefaultsToService) {
  const SecurityDir pki("service");
  auto config = parse_config("dds:\n  security:\n    dir: " + pki.path() + "\n", "cell.yaml");
  ASSERT_TRUE(config.ok()) << config.error().message;
  EXPECT_EQ(config->participant.security_identity, "service");
  EXPECT_TRUE(default_config().participant.security_dir.empty());  // no security unless asked
  EXPECT_TRUE(default_config().participant.discovery_servers.empty());
}

TEST(Config, DdsDeploymentErrorsNameTheKeyAndTheLine) {
  EXPECT_THAT(
      parse_error("dds:\n  discovery_servers:\n    - 127.0.0.1:11811\n"
                  "    - 127.0.0.1:99999\n"),
      AllOf(HasSubstr("cell.yaml:4:"), HasSubstr("dds.discovery_servers[1]"), HasSubstr("port")));
  EXPECT_THAT(parse_error("dds:\n  discovery_servers: 10.0.0.2\n"),
              AllOf(HasSubstr("cell.yaml:2:"), HasSubstr("expected a list")));
  EXPECT_THAT(parse_error("dds:\n  xml_profile_file: /nonexistent/dh3.xml\n"),
              AllOf(HasSubstr("cell.yaml:2:"), HasSubstr("dds.xml_profile_file"),
                    HasSubstr("/nonexistent/dh3.xml")));
  EXPECT_THAT(parse_error("dds:\n  udp_only: true\n  shared_memory: true\n"),
              AllOf(HasSubstr("cell.yaml:3:"), HasSubstr("dds.shared_memory"),
                    HasSubstr("contradicts dds.udp_only")));
  EXPECT_THAT(parse_error("dds:\n  udp_only: true\n  xml_profile: dh3_udp\n"),
              AllOf(HasSubstr("cell.yaml:3:"), HasSubstr("needs dds.xml_profile_file")));
  EXPECT_THAT(
      parse_error("dds:\n  security:\n    identity: service\n"),
      AllOf(HasSubstr("cell.yaml:3:"), HasSubstr("dds.security.dir"), HasSubstr("missing")));
  EXPECT_THAT(
      parse_error("dds:\n  security: {dir: /tmp, mode: strict}\n"),
      AllOf(HasSubstr("cell.yaml:2:"), HasSubstr("dds.security.mode"), HasSubstr("unknown key")));

  const SecurityDir pki("service");
  const auto error = [](const std::string& yaml) {
    auto result = parse_config(yaml, "cell.yaml");
    EXPECT_FALSE(result.ok()) << "accepted:\n" << yaml;
    return result.ok() ? std::string{} : result.error().message;
  };
  // A missing credential is named, at the directory's line.
  pki.remove("service/key.pem");
  EXPECT_THAT(error("dds:\n  security:\n    dir: " + pki.path() + "\n"),
              AllOf(HasSubstr("cell.yaml:3:"), HasSubstr("dds.security.dir"),
                    HasSubstr("private key"), HasSubstr("service/key.pem")));
  // An identity that is not there (the files of another one are).
  EXPECT_THAT(error("dds:\n  security:\n    dir: " + pki.path() + "\n    identity: monitor\n"),
              AllOf(HasSubstr("identity 'monitor'"), HasSubstr("monitor/cert.pem")));
  // The identity is a sub-directory's name, not a path.
  EXPECT_THAT(error("dds:\n  security:\n    dir: " + pki.path() + "\n    identity: ../etc\n"),
              AllOf(HasSubstr("cell.yaml:4:"), HasSubstr("dds.security.identity"),
                    HasSubstr("plain name")));
}

TEST(Config, CommandLineSetsDiscoveryServersXmlAndSecurity) {
  const SecurityDir pki("monitor");
  auto file = parse_config("dds:\n  discovery_servers: [10.0.0.9:11811]\n", "cell.yaml");
  ASSERT_TRUE(file.ok()) << file.error().message;
  file->buses = default_config().buses;
  CommandLine line;
  line.discovery_servers = {"127.0.0.1:11811", "127.0.0.1:11812"};
  line.xml_profile_file = pki.xml();
  line.xml_profile = "dh3_udp";
  line.security_dir = pki.path();
  line.security_identity = "monitor";
  auto config = apply_command_line(std::move(*file), line);
  ASSERT_TRUE(config.ok()) << config.error().message;
  // --discovery-server replaces the file's list.
  EXPECT_THAT(config->participant.discovery_servers,
              ::testing::ElementsAre("127.0.0.1:11811", "127.0.0.1:11812"));
  EXPECT_EQ(config->participant.xml_profile_file, pki.xml());
  EXPECT_EQ(config->participant.xml_profile, "dh3_udp");
  EXPECT_EQ(config->participant.security_dir, pki.path());
  EXPECT_EQ(config->participant.security_identity, "monitor");
}

TEST(Config, BadDeploymentOptionsNameTheOption) {
  const auto error = [](CommandLine line) {
    auto config = apply_command_line(default_config(), line);
    EXPECT_FALSE(config.ok());
    return config.ok() ? std::string{} : config.error().message;
  };
  const SecurityDir pki("service");
  CommandLine line;
  line.discovery_servers = {"10.0.0.1:0"};
  EXPECT_THAT(error(line), AllOf(HasSubstr("--discovery-server"), HasSubstr("10.0.0.1:0")));
  line = {};
  line.discovery_servers = {"1.2.3"};
  EXPECT_THAT(error(line), HasSubstr("--discovery-server"));
  line = {};
  line.xml_profile_file = "/nonexistent/dh3.xml";
  EXPECT_THAT(error(line), AllOf(HasSubstr("--xml"), HasSubstr("/nonexistent/dh3.xml")));
  line = {};
  line.xml_profile = "dh3_udp";
  EXPECT_THAT(error(line), AllOf(HasSubstr("--profile"), HasSubstr("--xml")));
  line = {};
  line.security_dir = pki.path();
  line.security_identity = "operator";  // no such identity in the directory
  EXPECT_THAT(error(line), AllOf(HasSubstr("--security-dir"), HasSubstr("operator/cert.pem")));
  line = {};
  line.security_dir = "/nonexistent/pki";
  EXPECT_THAT(error(line), AllOf(HasSubstr("--security-dir"), HasSubstr("identity CA")));
  line = {};
  line.security_dir = pki.path();
  line.security_identity = "a/b";
  EXPECT_THAT(error(line), AllOf(HasSubstr("--security-identity"), HasSubstr("plain name")));
}

TEST(Config, BusNamesDefaultByPosition) {
  EXPECT_EQ(default_bus_name("sim", 0), "bus0");
  EXPECT_EQ(default_bus_name("tcp:127.0.0.1:9000", 3), "bus3");
  EXPECT_EQ(default_bus_name("socketcan:can0", 1), "can0");
}

TEST(Config, MetricsAddressComesFromTheFileAndTheCommandLineWins) {
  EXPECT_TRUE(default_config().metrics_address.empty());  // off unless asked for
  auto config = parse_ok("metrics: 127.0.0.1:9464\nbuses: [{spec: sim}]\n");
  EXPECT_EQ(config.metrics_address, "127.0.0.1:9464");

  CommandLine line;
  line.metrics_address = "0.0.0.0:0";
  auto overridden = apply_command_line(config, line);
  ASSERT_TRUE(overridden.ok()) << overridden.error().message;
  EXPECT_EQ(overridden->metrics_address, "0.0.0.0:0");

  line.metrics_address = "";  // --metrics "" turns the file's endpoint off
  auto off = apply_command_line(config, line);
  ASSERT_TRUE(off.ok()) << off.error().message;
  EXPECT_TRUE(off->metrics_address.empty());
}

TEST(Config, ARealBusMayGiveItsBitRate) {
  auto config = parse_ok("buses:\n  - {spec: 'tcp:127.0.0.1:9000', bit_rate: 500000}\n");
  ASSERT_EQ(config.buses.size(), 1U);
  EXPECT_EQ(config.buses[0].bit_rate, 500'000U);
  EXPECT_THAT(parse_error("buses:\n  - {spec: sim, bit_rate: 500000}\n"),
              AllOf(HasSubstr("buses[0].bit_rate"), HasSubstr("sim.bit_rate")));
}

TEST(Config, BadMetricsAddressesNameTheKeyOrOption) {
  EXPECT_THAT(parse_error("buses: [{spec: sim}]\nmetrics: localhost:9464\n"),
              AllOf(HasSubstr("cell.yaml:2: metrics:"), HasSubstr("localhost:9464")));
  CommandLine line;
  line.metrics_address = "127.0.0.1";
  auto config = apply_command_line(default_config(), line);
  ASSERT_FALSE(config.ok());
  EXPECT_THAT(config.error().message, AllOf(HasSubstr("--metrics"), HasSubstr("HOST:PORT")));
}

TEST(Config, ABusIsRecordedWhenItsFileSaysSo) {
  auto config = parse_ok(
      "buses:\n  - spec: sim\n    record: {dir: /var/lib/dh3/rec, max_file_bytes: 8192, "
      "max_files: 3}\n  - spec: sim:4\n");
  ASSERT_EQ(config.buses.size(), 2U);
  ASSERT_TRUE(config.buses[0].record.has_value());
  EXPECT_EQ(config.buses[0].record->dir, "/var/lib/dh3/rec");
  EXPECT_EQ(config.buses[0].record->max_file_bytes, 8192U);
  EXPECT_EQ(config.buses[0].record->max_files, 3U);
  EXPECT_FALSE(config.buses[1].record.has_value());
  const auto defaults = parse_ok("buses:\n  - {spec: sim, record: {dir: rec}}\n");
  EXPECT_EQ(defaults.buses[0].record, bus::RecorderOptions{"rec"});
}

TEST(Config, RecorderMistakesNameTheKeyAndTheLine) {
  EXPECT_THAT(parse_error("buses:\n  - spec: sim\n    record: {max_files: 3}\n"),
              HasSubstr("cell.yaml:3: buses[0].record.dir: missing"));
  EXPECT_THAT(parse_error("buses:\n  - spec: sim\n    record: {dir: r, max_file_bytes: 10}\n"),
              HasSubstr("buses[0].record.max_file_bytes: 10 is out of range"));
  EXPECT_THAT(parse_error("buses:\n  - spec: sim\n    record: {dir: r, max_files: 0}\n"),
              HasSubstr("buses[0].record.max_files: 0 is out of range"));
  EXPECT_THAT(parse_error("buses:\n  - spec: sim\n    record: {dir: r, size: 1}\n"),
              HasSubstr("buses[0].record.size: unknown key"));
  EXPECT_THAT(parse_error("buses:\n  - spec: sim\n    record: /tmp\n"),
              HasSubstr("buses[0].record: expected a mapping"));
}

TEST(Config, RecordOnTheCommandLineRecordsEveryBusKeepingTheFilesCaps) {
  auto config = parse_ok(
      "buses:\n  - {spec: sim, record: {dir: a, max_files: 2}}\n  - {spec: 'sim:4'}\n");
  CommandLine line;
  line.record_dir = "/tmp/rec";
  auto recorded = apply_command_line(config, line);
  ASSERT_TRUE(recorded.ok()) << recorded.error().message;
  for (const BusSettings& bus : recorded->buses) {
    ASSERT_TRUE(bus.record.has_value()) << bus.name;
    EXPECT_EQ(bus.record->dir, "/tmp/rec");
  }
  EXPECT_EQ(recorded->buses[0].record->max_files, 2U);
  EXPECT_EQ(recorded->buses[1].record->max_files, bus::RecorderOptions{}.max_files);
  line.record_dir = "";
  auto empty = apply_command_line(config, line);
  ASSERT_FALSE(empty.ok());
  EXPECT_THAT(empty.error().message, HasSubstr("--record"));
}

TEST(Config, RoleIsActiveUnlessTheFileOrTheCommandLineSaysStandby) {
  EXPECT_EQ(default_config().role, kRoleActive);
  const auto from_file = parse_ok("role: standby\nbuses:\n  - {name: can0, spec: 'socketcan:can0'}\n");
  EXPECT_EQ(from_file.role, kRoleStandby);
  CommandLine line;
  line.role = "active";
  const auto overridden = apply_command_line(from_file, line);
  ASSERT_TRUE(overridden.ok()) << overridden.error().message;
  EXPECT_EQ(overridden->role, kRoleActive);
  EXPECT_THAT(parse_error("role: backup\n"), AllOf(HasSubstr("role"), HasSubstr("active, standby")));
}

TEST(Config, AStandbyRefusesABusSimulatedInItsProcess) {
  // An auto member stands by at start, so it refuses one too.
  for (const std::string role : {"standby", "auto"}) {
    CommandLine line;
    line.role = role;
    line.buses = {"sim:1,2"};
    const auto refused = apply_command_line(default_config(), line);
    ASSERT_FALSE(refused.ok());
    EXPECT_THAT(refused.error().message,
                HasSubstr("role: " + role + ": bus 'bus0' (sim:1,2) is simulated"));
    line.buses = {"tcp:127.0.0.1:5000"};
    EXPECT_TRUE(apply_command_line(default_config(), line).ok());
  }
}

TEST(Config, RoleAutoIsAccepted) {
  const auto from_file = parse_ok("role: auto\nbuses:\n  - {name: can0, spec: 'socketcan:can0'}\n");
  EXPECT_EQ(from_file.role, kRoleAuto);
  EXPECT_THAT(parse_error("role: primary\n"), HasSubstr("active, standby, auto"));
}

}  // namespace
}  // namespace dh3::app
