// The configuration keys are declared once (config_keys.hpp): the parser
// accepts exactly the declared keys with the declared ranges, its defaults are
// the declared ones, and docs/configuration.md's table is the declaration's.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>

#include "dh3/app/config.hpp"
#include "dh3/app/config_keys.hpp"

namespace dh3::app {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

// A file in which the key at `path` (a leaf) has `value`: each list level is
// one element, and a bus is a sim bus (so the sim-only keys are allowed).
std::string file_with(std::string_view path, const std::string& value) {
  if (path.starts_with("buses[].hands[].")) {
    const auto key = path.substr(16);
    const std::string id = key == "id" ? value : "1";
    std::string hand = "{id: " + id;
    if (key != "id") hand += ", " + std::string(key) + ": " + value;
    return "buses:\n  - spec: sim\n    hands: [" + hand + "}]\n";
  }
  if (path.starts_with("buses[].record.")) {
    const auto key = path.substr(15);
    std::string record = "dir: /tmp";
    if (key != "dir") record += ", " + std::string(key) + ": " + value;
    return "buses:\n  - spec: sim\n    record: {" + record + "}\n";
  }
  if (path.starts_with("buses[].sim.")) {
    return "buses:\n  - spec: sim\n    sim: {" + std::string(path.substr(12)) + ": " + value + "}\n";
  }
  if (path.starts_with("buses[].")) {
    const auto key = path.substr(8);
    const std::string spec = key == "bit_rate" ? "tcp:127.0.0.1:9000" : "sim";
    return "buses:\n  - spec: " + spec + "\n    " + std::string(key) + ": " + value + "\n";
  }
  if (path.starts_with("dds.")) return "dds:\n  " + std::string(path.substr(4)) + ": " + value + "\n";
  return std::string(path) + ": " + value + "\n";
}

std::string whole(double value) {
  return std::to_string(static_cast<long long>(value));
}

TEST(ConfigKeys, EveryNumberIsRefusedJustOutsideItsDeclaredRangeAndTakenAtItsEnds) {
  int checked = 0;
  for (const ConfigKey& key : config_keys()) {
    if (key.type != KeyType::integer && key.type != KeyType::milliseconds) continue;
    SCOPED_TRACE(std::string(key.path));
    for (const double end : {key.min, key.max}) {
      const auto yaml = file_with(key.path, whole(end));
      const auto parsed = parse_config(yaml, "keys.yaml");
      EXPECT_TRUE(parsed.ok()) << yaml << (parsed.ok() ? "" : parsed.error().message);
    }
    for (const double outside : {key.min - 1, key.max + 1}) {
      const auto yaml = file_with(key.path, whole(outside));
      const auto parsed = parse_config(yaml, "keys.yaml");
      ASSERT_FALSE(parsed.ok()) << yaml;
      EXPECT_THAT(parsed.error().message, HasSubstr("out of range")) << yaml;
    }
    ++checked;
  }
  EXPECT_GT(checked, 20);
}

TEST(ConfigKeys, TheParserKnowsEveryDeclaredKeyUnderEachParent) {
  for (const auto* parent :
       {"", "dds", "dds.security", "buses[]", "buses[].sim", "buses[].record", "buses[].hands[]"}) {
    EXPECT_FALSE(child_keys(parent).empty()) << parent;
  }
  // An undeclared key is refused, and the message lists the declared ones.
  const auto parsed = parse_config("buses:\n  - spec: sim\n    max_line_load: 0.5\n", "keys.yaml");
  ASSERT_FALSE(parsed.ok());
  EXPECT_THAT(parsed.error().message, HasSubstr("unknown key"));
  for (const auto name : child_keys("buses[]")) {
    EXPECT_THAT(parsed.error().message, HasSubstr(std::string(name)));
  }
}

TEST(ConfigKeys, TheParsersDefaultsAreTheDeclaredOnes) {
  const auto parsed = parse_config("buses:\n  - spec: sim\n", "keys.yaml");
  ASSERT_TRUE(parsed.ok()) << parsed.error().message;
  const ServiceConfig& config = *parsed;
  const BusSettings& bus = config.buses.at(0);
  const auto ms = [](Duration d) {
    return std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(d).count());
  };
  const auto& s = bus.scheduler;
  const std::map<std::string, std::string> parsed_defaults = {
      {"name", config.name},
      {"domain", std::to_string(config.participant.domain)},
      {"log_level", config.log_level},
      {"allow_admin", config.allow_admin ? "true" : "false"},
      {"dds.security.identity", config.participant.security_identity},
      {"dds.status_refresh_ms", ms(config.status_refresh)},
      {"buses[].bit_rate", std::to_string(bus.bit_rate)},
      {"buses[].command_interval_ms", ms(s.command_interval)},
      {"buses[].poll_interval_watch_ms", ms(s.poll_interval_watch)},
      {"buses[].poll_interval_moving_ms", ms(s.poll_interval_moving)},
      {"buses[].poll_interval_idle_ms", ms(s.poll_interval_idle)},
      {"buses[].reply_timeout_ms", ms(s.reply_timeout)},
      {"buses[].admin_reply_timeout_ms", ms(s.admin_reply_timeout)},
      {"buses[].max_retries", std::to_string(s.max_retries)},
      {"buses[].offline_after_timeouts", std::to_string(s.offline_after_timeouts)},
      {"buses[].offline_probe_interval_ms", ms(s.offline_probe_interval)},
      {"buses[].init_timeout_ms", ms(s.init_timeout)},
      {"buses[].motion_timeout_ms", ms(s.motion_timeout)},
      {"buses[].queue_capacity", std::to_string(s.queue_capacity)},
      {"buses[].discovery_interval_ms", ms(s.discovery_interval)},
      {"buses[].probe_spacing_ms", ms(s.probe_spacing)},
      {"buses[].sim.reply_delay_ms", ms(bus.sim.reply_delay)},
      {"buses[].sim.init_time_ms", ms(bus.sim.init_time)},
      {"buses[].sim.bit_rate", std::to_string(bus.sim.bit_rate)},
      {"buses[].sim.position_speed", whole(bus.sim.position_speed)},
      {"buses[].sim.rotation_speed", whole(bus.sim.rotation_speed)},
      {"buses[].record.max_file_bytes", std::to_string(bus::RecorderOptions{}.max_file_bytes)},
      {"buses[].record.max_files", std::to_string(bus::RecorderOptions{}.max_files)},
  };
  for (const auto& [path, value] : parsed_defaults) {
    const ConfigKey* key = find_config_key(path);
    ASSERT_NE(key, nullptr) << path;
    EXPECT_EQ(key->fallback, value) << path;
  }
}

// A rule runs in one place: the command line's value meets the key's range
// and is refused with the file's words, naming the option instead of the line.
TEST(ConfigKeys, TheCommandLineMeetsTheKeysOwnRules) {
  const auto from_file = parse_config("domain: 233\n", "keys.yaml");
  ASSERT_FALSE(from_file.ok());
  EXPECT_EQ(from_file.error().message, "keys.yaml:1: domain: 233 is out of range (0-232)");
  CommandLine line;
  line.domain = 233;
  const auto from_line = apply_command_line(default_config(), line);
  ASSERT_FALSE(from_line.ok());
  EXPECT_EQ(from_line.error().message, "--domain: 233 is out of range (0-232)");

  line = {};
  line.security_identity = "../etc";
  const auto identity = apply_command_line(default_config(), line);
  ASSERT_FALSE(identity.ok());
  EXPECT_EQ(identity.error().message,
            "--security-identity: security identity '../etc' is not a plain name (letters, "
            "digits, '-', '_', '.')");
}

// --help's text for an option is its key's: the doc, the range and the
// default the option struct gives.
TEST(ConfigKeys, AnOptionsHelpIsItsKeysDeclaration) {
  const ConfigKey& domain = *find_config_key("domain");
  EXPECT_EQ(option_name(domain), "--domain");
  EXPECT_THAT(option_help("domain"), AllOf(HasSubstr(std::string(domain.doc)),
                                           HasSubstr("0-232"), HasSubstr("default 0")));
  EXPECT_THAT(option_help("log_level"), HasSubstr("default info"));
  EXPECT_THAT(option_help("name"), HasSubstr("default " + default_config().name));
}

// With neither a file nor --bus the service runs the simulator; a file lists
// its buses or --bus gives them, and the table, --help and the refusal say so.
TEST(ConfigKeys, WithoutBusesOnlyNoFileAtAllMeansTheSimulator) {
  const ConfigKey& buses = *find_config_key("buses");
  EXPECT_THAT(buses.fallback, AllOf(HasSubstr("no file and no --bus"), HasSubstr("sim:1,2,3 as bus0")));
  EXPECT_THAT(std::string(buses.doc), HasSubstr("needs --bus"));
  const ServiceConfig no_file = default_config();
  ASSERT_EQ(no_file.buses.size(), 1U);
  EXPECT_EQ(no_file.buses[0].name, "bus0");
  EXPECT_EQ(no_file.buses[0].spec, "sim:1,2,3");

  const auto file = parse_config("name: cell7\n", "cell.yaml");
  ASSERT_TRUE(file.ok()) << file.error().message;
  const auto refused = apply_command_line(*file, CommandLine{});
  ASSERT_FALSE(refused.ok());
  EXPECT_THAT(refused.error().message,
              AllOf(HasSubstr("no bus configured"), HasSubstr("--bus"), HasSubstr("config file")));
  CommandLine line;
  line.buses = {"sim"};
  const auto given = apply_command_line(*file, line);
  ASSERT_TRUE(given.ok()) << given.error().message;
  EXPECT_EQ(given->name, "cell7");
  EXPECT_EQ(given->buses.at(0).spec, "sim");
}

TEST(ConfigKeys, TheDocumentedTableIsTheDeclaration) {
  std::ifstream file(DH3_CONFIG_DOC);
  ASSERT_TRUE(file) << DH3_CONFIG_DOC;
  std::stringstream text;
  text << file.rdbuf();
  const std::string doc = text.str();
  const std::string begin = "<!-- config-keys: dh3-service --config-keys -->\n";
  const auto start = doc.find(begin);
  ASSERT_NE(start, std::string::npos) << "docs/configuration.md has no marked configuration table";
  const auto table_start = start + begin.size();
  const auto end = doc.find("\n\n", table_start);
  const std::string table = doc.substr(table_start, end - table_start + 1);
  EXPECT_EQ(table, config_keys_table())
      << "docs/configuration.md's configuration table differs from config_keys.cpp; replace it with the "
         "output of `dh3-service --config-keys`";
}

}  // namespace
}  // namespace dh3::app
