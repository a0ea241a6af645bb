#include "dh3/app/config.hpp"

#include <arpa/inet.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

#include "dh3/app/config_keys.hpp"
#include "dh3/bus/bus_spec.hpp"
#include "dh3/metrics/metrics_exporter.hpp"
#include "dh3_discovery_servers.hpp"
#include "dh3_idl/dh3.h"
#include "dh3_security_files.hpp"

namespace dh3::app {
namespace {

constexpr std::size_t kMaxNameLength = limits::MAX_NAME_LENGTH;
constexpr std::array<std::string_view, 7> kLogLevels{"trace", "debug",    "info", "warn",
                                                     "error", "critical", "off"};

// Checks shared by the file and the command line: fine, or what is wrong with
// the value.
using Checked = Result<void, std::string>;

Checked check_name(std::string_view what, std::string_view name) {
  if (name.empty()) return fail(std::string(what) + " is empty");
  if (name.size() > kMaxNameLength) {
    return fail(std::string(what) + " '" + std::string(name) + "' is longer than " +
                std::to_string(kMaxNameLength) + " characters");
  }
  return {};
}

// The command line's --domain takes the file's key's range.
Checked check_domain(long long domain) {
  const ConfigKey& key = *find_config_key("domain");
  const auto min = static_cast<long long>(key.min);
  const auto max = static_cast<long long>(key.max);
  if (domain < min || domain > max) {
    return fail("domain " + std::to_string(domain) + " is out of range (" + std::to_string(min) +
                "-" + std::to_string(max) + ")");
  }
  return {};
}

Checked check_log_level(std::string_view level) {
  if (std::find(kLogLevels.begin(), kLogLevels.end(), level) != kLogLevels.end()) {
    return {};
  }
  return fail("log level '" + std::string(level) +
              "' is not one of trace, debug, info, warn, error, critical, off");
}

Checked check_interface(std::string_view address) {
  if (address == "*") return {};
  in_addr parsed{};
  if (inet_pton(AF_INET, std::string(address).c_str(), &parsed) == 1) return {};
  return fail("interface '" + std::string(address) + "' is not an IPv4 address (or \"*\" for all)");
}

Checked check_discovery_server(std::string_view entry) {
  // One entry on its own: its position (the server id) cannot be wrong here,
  // only its text; empty entries are allowed (they skip an id).
  auto list = contract::discovery_servers_from_entries({std::string(entry)});
  if (!list) return fail(std::move(list).error());
  return {};
}

Checked check_readable_file(std::string_view what, const std::string& path) {
  if (path.empty()) return fail(std::string(what) + " is empty");
  if (::access(path.c_str(), R_OK) != 0) {
    return fail("cannot read the " + std::string(what) + " '" + path + "'");
  }
  return {};
}

// The identity names a sub-directory of the security directory: a plain name,
// so that it cannot point elsewhere.
Checked check_identity(std::string_view identity) {
  if (identity.empty()) return fail(std::string("the security identity is empty"));
  if (identity == "." || identity == ".." ||
      identity.find_first_not_of(
          "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_.") !=
          std::string_view::npos) {
    return fail("security identity '" + std::string(identity) +
                "' is not a plain name (letters, digits, '-', '_', '.')");
  }
  return {};
}

Checked check_security(const std::string& dir, const std::string& identity) {
  if (dir.empty()) return fail(std::string("the security directory is empty"));
  if (auto checked = check_identity(identity); !checked) return checked;
  auto readable = contract::check_security_files(contract::security_files_in(dir, identity));
  if (!readable) return fail(readable.error() + " (identity '" + identity + "' in '" + dir + "')");
  return {};
}

Checked check_spec(std::string_view spec) {
  auto parsed = bus::parse_bus_spec(spec);
  if (!parsed) return fail(parsed.error());
  return {};
}

/// A mistake in the file: where it is and what is wrong. Thrown inside the
/// parser only; parse_config() turns it into a ConfigError.
struct FileError {
  std::string message;
};

class FileParser {
 public:
  explicit FileParser(std::string_view source) : source_(source) {}

  ServiceConfig parse(const YAML::Node& root) {
    ServiceConfig config;
    if (!root || root.IsNull()) return config;  // an empty file: every default
    expect_map(root, "the configuration");
    check_keys(root, "", "");
    if (auto n = root["name"]) config.name = name(n, "name", "service name");
    if (auto n = root["domain"]) {
      const auto domain = integer(n, "domain", "domain");
      config.participant.domain = static_cast<int>(domain);
    }
    if (auto n = root["log_level"]) {
      config.log_level = scalar(n, "log_level");
      require(n, "log_level", check_log_level(config.log_level));
    }
    if (auto n = root["allow_admin"]) config.allow_admin = boolean(n, "allow_admin");
    if (auto n = root["metrics"]) {
      config.metrics_address = scalar(n, "metrics");
      require(n, "metrics", metrics::check_listen_address(config.metrics_address));
    }
    if (auto dds = root["dds"]) parse_dds(dds, config);
    if (auto buses = root["buses"]) {
      if (!buses.IsSequence()) fail_at(buses, "buses", "expected a list of buses");
      std::set<std::string> names;
      for (std::size_t i = 0; i < buses.size(); ++i) {
        config.buses.push_back(parse_bus(buses[i], i, names));
      }
    }
    return config;
  }

 private:
  [[noreturn]] void fail_at(const YAML::Node& node, std::string_view key,
                            std::string_view what) const {
    std::ostringstream out;
    out << source_ << ":" << node.Mark().line + 1 << ": " << key << ": " << what;
    throw FileError{out.str()};
  }

  void require(const YAML::Node& node, std::string_view key, const Checked& checked) const {
    if (!checked) fail_at(node, key, checked.error());
  }

  void expect_map(const YAML::Node& node, std::string_view key) const {
    if (!node.IsMap()) fail_at(node, key, "expected a mapping of keys to values");
  }

  /// Every key of `map` is declared under `parent` (config_keys.hpp).
  void check_keys(const YAML::Node& map, std::string_view prefix, std::string_view parent) const {
    const auto known = child_keys(parent);
    for (const auto& entry : map) {
      const auto key = entry.first.as<std::string>();
      if (std::find(known.begin(), known.end(), key) != known.end()) continue;
      std::string list;
      for (const auto k : known) list += (list.empty() ? "" : ", ") + std::string(k);
      fail_at(entry.first, std::string(prefix) + key, "unknown key (known here: " + list + ")");
    }
  }

  std::string scalar(const YAML::Node& node, std::string_view key) const {
    if (!node.IsScalar()) fail_at(node, key, "expected a single value");
    return node.Scalar();
  }

  std::string name(const YAML::Node& node, std::string_view key, std::string_view what) const {
    auto value = scalar(node, key);
    require(node, key, check_name(what, value));
    return value;
  }

  /// The declaration of `path`; every key the parser reads is declared.
  const ConfigKey& declared(const YAML::Node& node, std::string_view path) const {
    const ConfigKey* declared = find_config_key(path);
    if (declared == nullptr) fail_at(node, path, "not declared in config_keys.cpp");
    return *declared;
  }

  long long integer(const YAML::Node& node, std::string_view key, std::string_view path) const {
    const ConfigKey& declaration = declared(node, path);
    const auto min = static_cast<long long>(declaration.min);
    const auto max = static_cast<long long>(declaration.max);
    const auto text = scalar(node, key);
    long long value = 0;
    try {
      value = node.as<long long>();
    } catch (const YAML::Exception&) {
      fail_at(node, key, "'" + text + "' is not an integer");
    }
    if (value < min || value > max) {
      fail_at(node, key,
              text + " is out of range (" + std::to_string(min) + "-" + std::to_string(max) + ")");
    }
    return value;
  }

  double number(const YAML::Node& node, std::string_view key, std::string_view path) const {
    const ConfigKey& declaration = declared(node, path);
    const double min = declaration.min;
    const double max = declaration.max;
    const auto text = scalar(node, key);
    double value = 0;
    try {
      value = node.as<double>();
    } catch (const YAML::Exception&) {
      fail_at(node, key, "'" + text + "' is not a number");
    }
    if (!(value >= min && value <= max)) {
      std::ostringstream range;
      range << text << " is out of range (" << min << "-" << max << ")";
      fail_at(node, key, range.str());
    }
    return value;
  }

  Duration millis(const YAML::Node& node, std::string_view key, std::string_view path) const {
    return std::chrono::milliseconds(integer(node, key, path));
  }

  bool boolean(const YAML::Node& node, std::string_view key) const {
    const auto text = scalar(node, key);
    try {
      return node.as<bool>();
    } catch (const YAML::Exception&) {
      fail_at(node, key, "'" + text + "' is not true or false");
    }
  }

  void parse_dds(const YAML::Node& dds, ServiceConfig& config) const {
    expect_map(dds, "dds");
    check_keys(dds, "dds.", "dds");
    if (auto n = dds["status_refresh_ms"]) {
      config.status_refresh = millis(n, "dds.status_refresh_ms", "dds.status_refresh_ms");
    }
    if (auto list = dds["interfaces"]) {
      if (!list.IsSequence()) fail_at(list, "dds.interfaces", "expected a list of IPv4 addresses");
      for (std::size_t i = 0; i < list.size(); ++i) {
        const std::string key = "dds.interfaces[" + std::to_string(i) + "]";
        auto address = scalar(list[i], key);
        require(list[i], key, check_interface(address));
        config.participant.interfaces.push_back(std::move(address));
      }
      if (config.participant.interfaces.size() > 1 &&
          std::find(config.participant.interfaces.begin(), config.participant.interfaces.end(),
                    "*") != config.participant.interfaces.end()) {
        fail_at(list, "dds.interfaces", "\"*\" (all interfaces) cannot be combined with addresses");
      }
    }
    if (auto n = dds["udp_only"]) config.participant.udp_only = boolean(n, "dds.udp_only");
    if (auto n = dds["shared_memory"]) {
      config.participant.shared_memory = boolean(n, "dds.shared_memory");
      if (config.participant.shared_memory && config.participant.udp_only) {
        fail_at(n, "dds.shared_memory", "contradicts dds.udp_only: give one of them");
      }
    }
    if (auto list = dds["discovery_servers"]) {
      if (!list.IsSequence()) {
        fail_at(list, "dds.discovery_servers", "expected a list of HOST[:PORT] entries");
      }
      for (std::size_t i = 0; i < list.size(); ++i) {
        const std::string key = "dds.discovery_servers[" + std::to_string(i) + "]";
        // A null entry ("- ~" or "- ''") skips a server id, as in ROS_DISCOVERY_SERVER.
        auto entry = list[i].IsNull() ? std::string() : scalar(list[i], key);
        require(list[i], key, check_discovery_server(entry));
        config.participant.discovery_servers.push_back(std::move(entry));
      }
    }
    if (auto n = dds["xml_profile_file"]) {
      config.participant.xml_profile_file = scalar(n, "dds.xml_profile_file");
      require(n, "dds.xml_profile_file",
              check_readable_file("XML profiles file", config.participant.xml_profile_file));
    }
    if (auto n = dds["xml_profile"]) {
      config.participant.xml_profile = scalar(n, "dds.xml_profile");
      if (config.participant.xml_profile.empty())
        fail_at(n, "dds.xml_profile", "the profile name is empty");
      if (config.participant.xml_profile_file.empty()) {
        fail_at(n, "dds.xml_profile", "a profile needs dds.xml_profile_file, the file defining it");
      }
    }
    if (auto security = dds["security"]) parse_security(security, config);
  }

  void parse_security(const YAML::Node& security, ServiceConfig& config) const {
    expect_map(security, "dds.security");
    check_keys(security, "dds.security.", "dds.security");
    const auto dir = security["dir"];
    if (!dir) fail_at(security, "dds.security.dir", "missing (the directory with the credentials)");
    config.participant.security_dir = scalar(dir, "dds.security.dir");
    if (auto n = security["identity"]) {
      config.participant.security_identity = scalar(n, "dds.security.identity");
      require(n, "dds.security.identity", check_identity(config.participant.security_identity));
    }
    require(dir, "dds.security.dir",
            check_security(config.participant.security_dir, config.participant.security_identity));
  }

  BusSettings parse_bus(const YAML::Node& node, std::size_t index, std::set<std::string>& names) {
    const std::string key = "buses[" + std::to_string(index) + "]";
    expect_map(node, key);
    check_keys(node, key + ".", "buses[]");
    BusSettings bus;
    const auto spec = node["spec"];
    if (!spec) fail_at(node, key + ".spec", "missing (e.g. sim:1,2,3, tcp:HOST:PORT)");
    bus.spec = scalar(spec, key + ".spec");
    require(spec, key + ".spec", check_spec(bus.spec));
    const bool is_sim = bus::parse_bus_spec(bus.spec)->kind == bus::BusKind::sim;

    if (auto n = node["name"]) {
      bus.name = name(n, key + ".name", "bus name");
    } else {
      bus.name = default_bus_name(bus.spec, index);
    }
    if (!names.insert(bus.name).second) {
      fail_at(node["name"] ? node["name"] : node, key + ".name",
              "bus name '" + bus.name + "' is used twice");
    }

    auto& s = bus.scheduler;
    const auto timing = [&](const char* field, Duration& target) {
      if (auto n = node[field]) target = millis(n, key + "." + field, std::string("buses[].") + field);
    };
    timing("command_interval_ms", s.command_interval);
    if (auto n = node["interval_margin_ms"])
      bus.interval_margin = millis(n, key + ".interval_margin_ms", "buses[].interval_margin_ms");
    timing("poll_interval_watch_ms", s.poll_interval_watch);
    timing("poll_interval_moving_ms", s.poll_interval_moving);
    timing("poll_interval_idle_ms", s.poll_interval_idle);
    timing("reply_timeout_ms", s.reply_timeout);
    timing("admin_reply_timeout_ms", s.admin_reply_timeout);
    timing("offline_probe_interval_ms", s.offline_probe_interval);
    timing("init_timeout_ms", s.init_timeout);
    timing("motion_timeout_ms", s.motion_timeout);
    timing("discovery_interval_ms", s.discovery_interval);
    timing("probe_spacing_ms", s.probe_spacing);
    if (auto n = node["max_retries"]) {
      s.max_retries = static_cast<int>(integer(n, key + ".max_retries", "buses[].max_retries"));
    }
    if (auto n = node["offline_after_timeouts"]) {
      s.offline_after_timeouts =
          static_cast<int>(integer(n, key + ".offline_after_timeouts", "buses[].offline_after_timeouts"));
    }
    if (auto n = node["queue_capacity"]) {
      s.queue_capacity =
          static_cast<std::size_t>(integer(n, key + ".queue_capacity", "buses[].queue_capacity"));
    }

    if (auto n = node["bit_rate"]) {
      if (is_sim) fail_at(n, key + ".bit_rate", "a sim bus takes sim.bit_rate");
      bus.bit_rate = static_cast<std::uint32_t>(integer(n, key + ".bit_rate", "buses[].bit_rate"));
    }
    if (auto sim = node["sim"]) {
      if (!is_sim) fail_at(sim, key + ".sim", "only a sim bus has simulator settings");
      parse_sim(sim, key + ".sim", bus.sim);
    }
    if (auto n = node["record"]) bus.record = parse_record(n, key + ".record");
    if (auto hands = node["hands"]) {
      if (!hands.IsSequence() && !hands.IsNull()) {
        fail_at(hands, key + ".hands", "expected a list of hands ({id: 1, name: left})");
      }
      std::set<int> ids;
      for (std::size_t i = 0; i < hands.size(); ++i) {
        bus.hands.push_back(
            parse_hand(hands[i], key + ".hands[" + std::to_string(i) + "]", is_sim, ids));
      }
    }
    return bus;
  }

  void parse_sim(const YAML::Node& node, const std::string& key, SimSettings& sim) const {
    expect_map(node, key);
    check_keys(node, key + ".", "buses[].sim");
    if (auto n = node["reply_delay_ms"]) {
      sim.reply_delay = millis(n, key + ".reply_delay_ms", "buses[].sim.reply_delay_ms");
    }
    if (auto n = node["position_speed"]) {
      sim.position_speed = number(n, key + ".position_speed", "buses[].sim.position_speed");
    }
    if (auto n = node["rotation_speed"]) {
      sim.rotation_speed = number(n, key + ".rotation_speed", "buses[].sim.rotation_speed");
    }
    if (auto n = node["init_time_ms"]) {
      sim.init_time = millis(n, key + ".init_time_ms", "buses[].sim.init_time_ms");
    }
    if (auto n = node["bit_rate"]) {
      sim.bit_rate =
          static_cast<std::uint32_t>(integer(n, key + ".bit_rate", "buses[].sim.bit_rate"));
    }
  }

  bus::RecorderOptions parse_record(const YAML::Node& node, const std::string& key) const {
    expect_map(node, key);
    check_keys(node, key + ".", "buses[].record");
    bus::RecorderOptions record;
    const auto dir = node["dir"];
    if (!dir) fail_at(node, key + ".dir", "missing (the directory the recording goes to)");
    record.dir = scalar(dir, key + ".dir");
    if (record.dir.empty()) fail_at(dir, key + ".dir", "the directory is empty");
    if (auto n = node["max_file_bytes"]) {
      record.max_file_bytes = integer(n, key + ".max_file_bytes", "buses[].record.max_file_bytes");
    }
    if (auto n = node["max_files"]) {
      record.max_files = integer(n, key + ".max_files", "buses[].record.max_files");
    }
    return record;
  }

  HandSettings parse_hand(const YAML::Node& node, const std::string& key, bool is_sim,
                          std::set<int>& ids) const {
    expect_map(node, key);
    check_keys(node, key + ".", "buses[].hands[]");
    HandSettings hand;
    const auto id = node["id"];
    if (!id) fail_at(node, key + ".id", "missing (the hand's CAN ID, 1-255)");
    hand.id = static_cast<std::uint8_t>(integer(id, key + ".id", "buses[].hands[].id"));
    if (!ids.insert(hand.id).second) {
      fail_at(id, key + ".id",
              "CAN ID " + std::to_string(hand.id) + " is listed twice on this bus");
    }
    if (auto n = node["name"]) {
      hand.name = scalar(n, key + ".name");
      if (hand.name.size() > kMaxNameLength) {
        fail_at(n, key + ".name", "longer than " + std::to_string(kMaxNameLength) + " characters");
      }
    }
    for (const char* field : {"object", "rotation_obstacle"}) {
      const auto n = node[field];
      if (!n) continue;
      if (!is_sim) {
        fail_at(n, key + "." + field,
                "only simulated hands have one (on a dh3-sim transfer box, give it to dh3-sim)");
      }
      const auto value = static_cast<std::int32_t>(
          integer(n, key + "." + field, std::string("buses[].hands[].") + field));
      (std::string_view(field) == "object" ? hand.object : hand.rotation_obstacle) = value;
    }
    return hand;
  }

  std::string source_;
};

}  // namespace

bool is_bare_sim_spec(std::string_view spec) {
  return spec == "sim";
}

std::string default_bus_name(std::string_view spec, std::size_t index) {
  if (auto parsed = bus::parse_bus_spec(spec);
      parsed && parsed->kind == bus::BusKind::socketcan && !parsed->interface.empty()) {
    return parsed->interface;
  }
  return "bus" + std::to_string(index);
}

Duration default_interval_margin(std::string_view spec) {
  const auto parsed = bus::parse_bus_spec(spec);
  const bool transfer_box =
      parsed && (parsed->kind == bus::BusKind::tcp || parsed->kind == bus::BusKind::serial);
  return transfer_box ? std::chrono::milliseconds(2) : Duration{};
}

ServiceConfig default_config() {
  ServiceConfig config;
  BusSettings bus;
  bus.name = "bus0";
  bus.spec = "sim:1,2,3";
  for (std::uint8_t id = 1; id <= 3; ++id) bus.hands.push_back(HandSettings{id, {}, {}, {}});
  config.buses.push_back(std::move(bus));
  return config;
}

Result<ServiceConfig, ConfigError> parse_config(std::string_view yaml, std::string_view source) {
  try {
    const YAML::Node root = YAML::Load(std::string(yaml));
    return FileParser(source).parse(root);
  } catch (const FileError& error) {
    return fail(ConfigError{error.message});
  } catch (const YAML::Exception& error) {
    // Syntax errors: yaml-cpp's mark is 0-based.
    std::ostringstream out;
    out << source << ":" << error.mark.line + 1 << ": " << error.msg;
    return fail(ConfigError{out.str()});
  }
}

Result<ServiceConfig, ConfigError> load_config(const std::string& path) {
  std::ifstream file(path);
  if (!file) return fail(ConfigError{"cannot read config file '" + path + "'"});
  std::ostringstream text;
  text << file.rdbuf();
  return parse_config(text.str(), path);
}

namespace {

/// A command line option applied to the configuration, or why it cannot be.
using Applied = Result<void, ConfigError>;

Failure<ConfigError> option_error(const std::string& option, const std::string& what) {
  return fail(ConfigError{option + ": " + what});
}

/// --name, --domain, --log-level, --allow-admin.
Applied apply_service_options(ServiceConfig& config, const CommandLine& line) {
  if (line.name) {
    if (auto checked = check_name("service name", *line.name); !checked)
      return option_error("--name", checked.error());
    config.name = *line.name;
  }
  if (line.domain) {
    if (auto checked = check_domain(*line.domain); !checked)
      return option_error("--domain", checked.error());
    config.participant.domain = *line.domain;
  }
  if (line.log_level) {
    if (auto checked = check_log_level(*line.log_level); !checked)
      return option_error("--log-level", checked.error());
    config.log_level = *line.log_level;
  }
  if (line.allow_admin) config.allow_admin = true;
  return {};
}

/// --udp-only, --shared-memory, --interface, --discovery-server.
Applied apply_transport_options(ServiceConfig& config, const CommandLine& line) {
  if (line.udp_only && line.shared_memory) {
    return option_error("--shared-memory", "contradicts --udp-only: give one of them");
  }
  if (line.udp_only || line.shared_memory) {
    config.participant.udp_only = line.udp_only;
    config.participant.shared_memory = line.shared_memory;
  }
  if (!line.interfaces.empty()) {
    for (const auto& address : line.interfaces) {
      if (auto checked = check_interface(address); !checked)
        return option_error("--interface", checked.error());
    }
    if (line.interfaces.size() > 1 &&
        std::find(line.interfaces.begin(), line.interfaces.end(), "*") != line.interfaces.end()) {
      return option_error("--interface",
                          "\"*\" (all interfaces) cannot be combined with addresses");
    }
    config.participant.interfaces = line.interfaces;
  }
  if (!line.discovery_servers.empty()) {
    for (const auto& entry : line.discovery_servers) {
      if (auto checked = check_discovery_server(entry); !checked)
        return option_error("--discovery-server", checked.error());
    }
    config.participant.discovery_servers = line.discovery_servers;
  }
  return {};
}

/// --xml and --profile; a profile needs its file.
Applied apply_xml_options(ServiceConfig& config, const CommandLine& line) {
  if (line.xml_profile_file) {
    if (auto checked = check_readable_file("XML profiles file", *line.xml_profile_file); !checked) {
      return option_error("--xml", checked.error());
    }
    config.participant.xml_profile_file = *line.xml_profile_file;
  }
  if (line.xml_profile) {
    if (line.xml_profile->empty()) return option_error("--profile", "the profile name is empty");
    config.participant.xml_profile = *line.xml_profile;
  }
  if (!config.participant.xml_profile.empty() && config.participant.xml_profile_file.empty()) {
    return option_error("--profile",
                        "a profile needs --xml FILE (or dds.xml_profile_file), the file "
                        "defining it");
  }
  return {};
}

/// --security-identity.
Applied apply_security_identity(ServiceConfig& config, const CommandLine& line) {
  if (line.security_identity) {
    if (auto checked = check_identity(*line.security_identity); !checked) {
      return option_error("--security-identity", checked.error());
    }
    config.participant.security_identity = *line.security_identity;
  }
  return {};
}

/// --metrics; empty turns the file's exporter off.
Applied apply_metrics_option(ServiceConfig& config, const CommandLine& line) {
  if (line.metrics_address) {
    if (!line.metrics_address->empty()) {
      if (auto checked = metrics::check_listen_address(*line.metrics_address); !checked) {
        return option_error("--metrics", checked.error());
      }
    }
    config.metrics_address = *line.metrics_address;
  }
  return {};
}

/// --security-dir, checked with the identity in use.
Applied apply_security_dir(ServiceConfig& config, const CommandLine& line) {
  if (line.security_dir) config.participant.security_dir = *line.security_dir;
  if (line.security_dir || (line.security_identity && !config.participant.security_dir.empty())) {
    if (auto checked =
            check_security(config.participant.security_dir, config.participant.security_identity);
        !checked) {
      return option_error(line.security_dir ? "--security-dir" : "--security-identity",
                          checked.error());
    }
  }
  return {};
}

/// --bus: the command line's buses replace the file's.
Applied apply_bus_options(ServiceConfig& config, const CommandLine& line) {
  if (!line.buses.empty()) {
    config.buses.clear();
    std::set<std::string> names;
    for (std::size_t i = 0; i < line.buses.size(); ++i) {
      const std::string& arg = line.buses[i];
      BusSettings bus;
      const auto equals = arg.find('=');
      bus.spec = equals == std::string::npos ? arg : arg.substr(equals + 1);
      bus.name =
          equals == std::string::npos ? default_bus_name(bus.spec, i) : arg.substr(0, equals);
      if (auto checked = check_spec(bus.spec); !checked)
        return option_error("--bus " + arg, checked.error());
      if (auto checked = check_name("bus name", bus.name); !checked)
        return option_error("--bus " + arg, checked.error());
      if (!names.insert(bus.name).second) {
        return option_error("--bus " + arg, "bus name '" + bus.name + "' is used twice");
      }
      config.buses.push_back(std::move(bus));
    }
  }
  return {};
}

/// --record DIR: every bus recorded into DIR (after --bus, which replaces the buses).
Applied apply_record_option(ServiceConfig& config, const CommandLine& line) {
  if (!line.record_dir) return {};
  if (line.record_dir->empty()) return option_error("--record", "the directory is empty");
  for (BusSettings& bus : config.buses) {
    if (!bus.record) bus.record.emplace();
    bus.record->dir = *line.record_dir;
  }
  return {};
}

}  // namespace

Result<ServiceConfig, ConfigError> apply_command_line(ServiceConfig config,
                                                      const CommandLine& line) {
  // In this order: with several bad options, the first one's error is reported.
  for (const auto apply :
       {apply_service_options, apply_transport_options, apply_xml_options, apply_security_identity,
        apply_metrics_option, apply_security_dir, apply_bus_options, apply_record_option}) {
    if (auto applied = apply(config, line); !applied) return fail(applied.error());
  }
  if (config.buses.empty()) {
    return fail(ConfigError{"no bus configured: give --bus SPEC or buses in the config file"});
  }
  return config;
}

}  // namespace dh3::app
