#include "dh3/app/config.hpp"

#include <yaml-cpp/yaml.h>

#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <type_traits>
#include <utility>

#include "config_checks.hpp"
#include "dh3/app/config_keys.hpp"
#include "dh3/bus/bus_spec.hpp"
#include "dh3/contract/participant_checks.hpp"

namespace dh3::app {
namespace {

/// A mistake in the file: where it is and what is wrong. Thrown inside the
/// parser only; parse_config() turns it into a ConfigError.
struct FileError {
  std::string message;
};

/// The key of a member of the participant's options: "security_dir" is
/// dds.security.dir, "udp_only" dds.udp_only.
std::string participant_key(std::string_view field) {
  constexpr std::string_view kSecurity = "security_";
  if (field.starts_with(kSecurity)) return "dds.security." + std::string(field.substr(kSecurity.size()));
  return "dds." + std::string(field);
}

/// The file's keys, read by walking the keys' table: each key's type, range
/// and rule come from its declaration; what is checked here is what spans
/// several keys.
class FileParser {
 public:
  explicit FileParser(std::string_view source) : source_(source) {}

  ServiceConfig parse(const YAML::Node& root) {
    ServiceConfig config;
    if (!root || root.IsNull()) return config;  // an empty file: every default
    ConfigTarget target{&config};
    read_map(root, "", "", target);
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

  std::string scalar(const YAML::Node& node, std::string_view key) const {
    if (!node.IsScalar()) fail_at(node, key, "expected a single value");
    return node.Scalar();
  }

  template <class T>
  T as(const YAML::Node& node, std::string_view key, std::string_view what) const {
    const auto text = scalar(node, key);
    try {
      return node.as<T>();
    } catch (const YAML::Exception&) {
      fail_at(node, key, "'" + text + "' is not " + std::string(what));
    }
  }

  /// The keys of `node`, the map at `scope` ("" for the root, "dds",
  /// "buses[]", ...); `where` names it in messages ("buses[0]").
  void read_map(const YAML::Node& node, std::string_view scope, const std::string& where,
                ConfigTarget& target) const {
    if (!node.IsMap()) {
      fail_at(node, where.empty() ? "the configuration" : where, "expected a mapping of keys to values");
    }
    const std::string prefix = where.empty() ? "" : where + ".";
    for (const auto& entry : node) {
      const auto name = entry.first.as<std::string>();
      const ConfigKey* key =
          find_config_key(scope.empty() ? name : std::string(scope) + "." + name);
      if (key == nullptr) {
        std::string known;
        for (const auto k : child_keys(scope)) known += (known.empty() ? "" : ", ") + std::string(k);
        fail_at(entry.first, prefix + name, "unknown key (known here: " + known + ")");
      }
      read_key(*key, entry.second, prefix + name, target);
    }
    for (const auto name : child_keys(scope)) {
      const ConfigKey& key = *find_config_key(scope.empty() ? name : std::string(scope) + "." + std::string(name));
      if (key.required && !node[std::string(name)]) {
        fail_at(node, prefix + std::string(name), "missing (" + std::string(key.doc) + ")");
      }
    }
    check_map(node, scope, where, target);
  }

  void read_key(const ConfigKey& key, const YAML::Node& node, const std::string& where,
                ConfigTarget& target) const {
    if (key.type == KeyType::map) {
      if (key.field.enter) key.field.enter(target);
      read_map(node, key.path, where, target);
    } else if (key.type == KeyType::list) {
      if (!node.IsSequence() && !node.IsNull()) {
        fail_at(node, where, "expected a list: " + std::string(key.doc));
      }
      if (key.field.enter) {
        read_elements(key, node, where, target);
      } else {
        read_texts(key, node, where, target);
      }
    } else {
      const ConfigValue value = leaf(key, node, where);
      require(node, where, check_value(key, value));
      key.field.store(target, value);
    }
  }

  ConfigValue leaf(const ConfigKey& key, const YAML::Node& node, const std::string& where) const {
    switch (key.type) {
      case KeyType::integer:
      case KeyType::milliseconds:
        return as<long long>(node, where, "an integer");
      case KeyType::number:
        return as<double>(node, where, "a number");
      case KeyType::boolean:
        return as<bool>(node, where, "true or false");
      default:
        return scalar(node, where);
    }
  }

  /// A list of maps (buses, hands): each element makes its object, then fills it.
  void read_elements(const ConfigKey& key, const YAML::Node& node, const std::string& where,
                     ConfigTarget& target) const {
    const std::string scope = std::string(key.path) + "[]";
    for (std::size_t i = 0; i < node.size(); ++i) {
      key.field.enter(target);
      read_map(node[i], scope, where + "[" + std::to_string(i) + "]", target);
    }
    check_list(node, key.path, where, target);
  }

  /// A list of texts, each element checked on its own.
  void read_texts(const ConfigKey& key, const YAML::Node& node, const std::string& where,
                  ConfigTarget& target) const {
    std::vector<std::string> items;
    for (std::size_t i = 0; i < node.size(); ++i) {
      const std::string item_key = where + "[" + std::to_string(i) + "]";
      // A null entry ("- ~") is an empty one: it skips a discovery server's id.
      auto item = node[i].IsNull() ? std::string() : scalar(node[i], item_key);
      require(node[i], item_key, check_value(key, item));
      items.push_back(std::move(item));
    }
    key.field.store(target, std::move(items));
  }

  /// What spans several keys of one map.
  void check_map(const YAML::Node& node, std::string_view scope, const std::string& where,
                 ConfigTarget& target) const {
    if (scope == "dds") {
      auto fits = contract::check_participant(target.config->participant, participant_key);
      if (!fits) {
        const std::string key = participant_key(fits.error().field);
        // The culprit's own line: dds.security.dir is node["security"]["dir"].
        YAML::Node culprit = node;
        std::string_view rest = std::string_view(key).substr(4);  // after "dds."
        for (auto dot = rest.find('.'); dot != std::string_view::npos; dot = rest.find('.')) {
          culprit = culprit[std::string(rest.substr(0, dot))];
          rest = rest.substr(dot + 1);
        }
        const YAML::Node at = culprit[std::string(rest)];
        fail_at(at ? at : node, key, fits.error().message);
      }
    } else if (scope == "buses[]") {
      check_simulator_keys(node, where, *target.bus);
    }
  }

  void check_simulator_keys(const YAML::Node& node, const std::string& where,
                            const BusSettings& bus) const {
    if (!bus::is_simulated(bus.spec)) {
      if (auto n = node["sim"]) fail_at(n, where + ".sim", "only a sim bus has simulator settings");
      for (std::size_t i = 0; i < bus.hands.size(); ++i) {
        for (const char* field : {"object", "rotation_obstacle"}) {
          if (auto n = node["hands"][i][field]) {
            fail_at(n, where + ".hands[" + std::to_string(i) + "]." + field,
                    "only simulated hands have one (on a dh3-sim transfer box, give it to dh3-sim)");
          }
        }
      }
    } else if (auto n = node["bit_rate"]) {
      fail_at(n, where + ".bit_rate", "a sim bus takes sim.bit_rate");
    }
  }

  /// What spans the elements of a list: names and CAN IDs once each.
  void check_list(const YAML::Node& node, std::string_view path, const std::string& where,
                  ConfigTarget& target) const {
    if (path == "buses") {
      std::set<std::string> names;
      auto& buses = target.config->buses;
      for (std::size_t i = 0; i < buses.size(); ++i) {
        if (!node[i]["name"]) buses[i].name = default_bus_name(buses[i].spec, i);
        if (!names.insert(buses[i].name).second) {
          fail_at(node[i]["name"] ? node[i]["name"] : node[i], where + "[" + std::to_string(i) + "].name",
                  "bus name '" + buses[i].name + "' is used twice");
        }
      }
    } else if (path == "buses[].hands") {
      std::set<int> ids;
      const auto& hands = target.bus->hands;
      for (std::size_t i = 0; i < hands.size(); ++i) {
        if (!ids.insert(hands[i].id).second) {
          fail_at(node[i]["id"], where + "[" + std::to_string(i) + "].id",
                  "CAN ID " + std::to_string(hands[i].id) + " is listed twice on this bus");
        }
      }
    }
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

/// Sets the key at `path` from the command line, through the key's own range
/// and rule; `option` names it in messages ("--domain", "--bus tcp:box").
Applied set_key(std::string_view path, ConfigTarget& target, ConfigValue value,
                const std::string& option) {
  const ConfigKey& key = *find_config_key(path);
  if (auto checked = check_value(key, value); !checked) {
    return fail(ConfigError{option + ": " + checked.error()});
  }
  key.field.store(target, value);
  return {};
}

/// An option's value if it was given.
template <class T>
std::optional<ConfigValue> given(const std::optional<T>& value) {
  if (!value) return std::nullopt;
  if constexpr (std::is_integral_v<T>) return ConfigValue(static_cast<long long>(*value));
  else return ConfigValue(*value);
}
std::optional<ConfigValue> given(const std::vector<std::string>& items) {
  return items.empty() ? std::nullopt : std::optional<ConfigValue>(items);
}
std::optional<ConfigValue> given_if(bool asked, bool value) {
  return asked ? std::optional<ConfigValue>(value) : std::nullopt;
}

/// The keys whose option was given, in the order their errors are reported.
Applied apply_service_options(ConfigTarget& target, const CommandLine& line) {
  // Either transport flag decides both: the command line's choice replaces the file's.
  const bool transport = line.udp_only || line.shared_memory;
  const std::pair<std::string_view, std::optional<ConfigValue>> given_keys[] = {
      {"name", given(line.name)},
      {"domain", given(line.domain)},
      {"log_level", given(line.log_level)},
      {"role", given(line.role)},
      {"allow_admin", given_if(line.allow_admin, true)},
      {"dds.udp_only", given_if(transport, line.udp_only)},
      {"dds.shared_memory", given_if(transport, line.shared_memory)},
      {"dds.interfaces", given(line.interfaces)},
      {"dds.discovery_servers", given(line.discovery_servers)},
      {"dds.xml_profile_file", given(line.xml_profile_file)},
      {"dds.xml_profile", given(line.xml_profile)},
      {"dds.security.identity", given(line.security_identity)},
      {"dds.security.dir", given(line.security_dir)},
      {"metrics", given(line.metrics_address)},
  };
  for (const auto& [path, value] : given_keys) {
    if (!value) continue;
    if (auto set = set_key(path, target, *value, option_name(*find_config_key(path))); !set) return set;
  }
  const auto option_of = [](std::string_view field) {
    return option_name(*find_config_key(participant_key(field)));
  };
  if (auto fits = contract::check_participant(target.config->participant, option_of); !fits) {
    return fail(ConfigError{option_of(fits.error().field) + ": " + fits.error().message});
  }
  return {};
}

/// --bus: the command line's buses replace the file's.
Applied apply_bus_options(ConfigTarget& target, const CommandLine& line) {
  if (line.buses.empty()) return {};
  auto& buses = target.config->buses;
  buses.clear();
  std::set<std::string> names;
  for (std::size_t i = 0; i < line.buses.size(); ++i) {
    const std::string& arg = line.buses[i];
    const auto equals = arg.find('=');
    const std::string spec = equals == std::string::npos ? arg : arg.substr(equals + 1);
    const std::string name =
        equals == std::string::npos ? default_bus_name(spec, i) : arg.substr(0, equals);
    target.bus = &buses.emplace_back();
    for (const auto& [path, value] : {std::pair{"buses[].spec", spec}, {"buses[].name", name}}) {
      if (auto set = set_key(path, target, value, "--bus " + arg); !set) return set;
    }
    if (!names.insert(name).second) {
      return fail(ConfigError{"--bus " + arg + ": bus name '" + name + "' is used twice"});
    }
  }
  return {};
}

/// --record DIR: every bus recorded into DIR (after --bus, which replaces the
/// buses); a bus's own `record:` keeps its caps.
Applied apply_record_option(ConfigTarget& target, const CommandLine& line) {
  if (!line.record_dir) return {};
  const std::string option = option_name(*find_config_key("buses[].record.dir"));
  for (BusSettings& bus : target.config->buses) {
    target.bus = &bus;
    if (!bus.record) bus.record.emplace();
    if (auto set = set_key("buses[].record.dir", target, *line.record_dir, option); !set) return set;
  }
  return {};
}

}  // namespace

Result<ServiceConfig, ConfigError> apply_command_line(ServiceConfig config,
                                                      const CommandLine& line) {
  ConfigTarget target{&config};
  // In this order: with several bad options, the first one's error is reported.
  for (const auto apply : {apply_service_options, apply_bus_options, apply_record_option}) {
    if (auto applied = apply(target, line); !applied) return fail(applied.error());
  }
  if (config.buses.empty()) {
    return fail(ConfigError{
        "no bus configured: give --bus SPEC or buses in the config file (only with neither a "
        "config file nor --bus does the service run the simulator)"});
  }
  if (config.role != kRoleActive) {
    for (const BusSettings& bus : config.buses) {
      if (!bus::is_simulated(bus.spec)) continue;
      return fail(ConfigError{
          "role: " + config.role + ": bus '" + bus.name + "' (" + bus.spec +
          ") is simulated inside this process: a standby must watch the hands its active "
          "service drives (a CAN interface, or a transfer box such as dh3-sim --shared)"});
    }
  }
  return config;
}

}  // namespace dh3::app
