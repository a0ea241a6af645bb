#include "dh3/app/config_keys.hpp"

#include <cmath>
#include <cstdio>
#include <optional>
#include <type_traits>

#include "config_checks.hpp"
#include "dh3/contract/participant_checks.hpp"
#include "dh3/contract/participant_flags.hpp"

// Each key names only what it has; the members it leaves out keep their
// defaults, which is what designated initializers are for here.
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"

namespace dh3::app {
namespace {

constexpr double kDay = 24.0 * 3600 * 1000;  // the longest time any key takes, in ms
constexpr double kMaxBitRate = 1'000'000;

using enum KeyType;

template <class T>
struct IsOptional : std::false_type {};
template <class T>
struct IsOptional<std::optional<T>> : std::true_type {};

std::string number_text(double value) {
  char text[32];
  if (value == std::floor(value)) {
    std::snprintf(text, sizeof text, "%.0f", value);
  } else {
    std::snprintf(text, sizeof text, "%g", value);
  }
  return text;
}

template <class T>
void assign(T& field, const ConfigValue& value) {
  if constexpr (IsOptional<T>::value) {
    typename T::value_type inner{};
    assign(inner, value);
    field = inner;
  } else if constexpr (std::is_same_v<T, bool>) {
    field = std::get<bool>(value);
  } else if constexpr (std::is_same_v<T, double>) {
    field = std::get<double>(value);
  } else if constexpr (std::is_integral_v<T>) {
    field = static_cast<T>(std::get<long long>(value));
  } else if constexpr (std::is_same_v<T, Duration>) {
    field = std::chrono::milliseconds(std::get<long long>(value));
  } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
    field = std::get<std::vector<std::string>>(value);
  } else {
    field = std::get<std::string>(value);  // text: std::string, std::filesystem::path
  }
}

template <class T>
std::string shown(const T& field) {
  if constexpr (IsOptional<T>::value) {
    return field ? shown(*field) : std::string();
  } else if constexpr (std::is_same_v<T, bool>) {
    return field ? "true" : "false";
  } else if constexpr (std::is_arithmetic_v<T>) {
    return number_text(static_cast<double>(field));
  } else if constexpr (std::is_same_v<T, Duration>) {
    return std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(field).count());
  } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
    std::string text;
    for (const auto& item : field) text += (text.empty() ? "" : ", ") + item;
    return text;
  } else {
    return std::string(field);
  }
}

template <class Access>
KeyField bind(Access access) {
  return KeyField{[access](ConfigTarget& t, const ConfigValue& v) { assign(access(t), v); },
                  [access](ConfigTarget& t) { return shown(access(t)); },
                  {}};
}

template <class T>
KeyField of_config(T ServiceConfig::*member) {
  return bind([member](ConfigTarget& t) -> T& { return t.config->*member; });
}
template <class T>
KeyField of_participant(T contract::ParticipantOptions::*member) {
  return bind([member](ConfigTarget& t) -> T& { return t.config->participant.*member; });
}
template <class T>
KeyField of_bus(T BusSettings::*member) {
  return bind([member](ConfigTarget& t) -> T& { return t.bus->*member; });
}
template <class T>
KeyField of_scheduler(T hand::SchedulerOptions::*member) {
  return bind([member](ConfigTarget& t) -> T& { return t.bus->scheduler.*member; });
}
template <class T>
KeyField of_sim(T SimSettings::*member) {
  return bind([member](ConfigTarget& t) -> T& { return t.bus->sim.*member; });
}
template <class T>
KeyField of_record(T bus::RecorderOptions::*member) {
  return bind([member](ConfigTarget& t) -> T& { return t.bus->record.value().*member; });
}
template <class T>
KeyField of_hand(T HandSettings::*member) {
  return bind([member](ConfigTarget& t) -> T& { return t.hand->*member; });
}
KeyField entered(std::function<void(ConfigTarget&)> enter) {
  return KeyField{{}, {}, std::move(enter)};
}

std::function<Checked(std::string_view)> named(std::string_view what) {
  return [what](std::string_view name) { return check_name(what, name); };
}
std::function<Checked(std::string_view)> not_empty(std::string_view what) {
  return [what](std::string_view text) { return check_not_empty(what, text); };
}

// Parents before their children; within a parent, the order the parser lists
// them in when it meets an unknown key.
std::vector<ConfigKey> declare_root_and_dds() {
  using P = contract::ParticipantOptions;
  return {
      {.path = "name", .type = text, .doc = "service name; requests address hands by it (1-64 characters)",
       .field = of_config(&ServiceConfig::name), .option = "-n,--name", .check = named("service name")},
      {.path = "domain", .type = integer, .max = contract::kMaxDomainId,
       .doc = "DDS domain id (Fast DDS's default port mapping ends at 232)",
       .field = of_participant(&P::domain), .option = contract::kDomainOption},
      {.path = "log_level", .doc = "trace, debug, info, warn, error, critical or off",
       .field = of_config(&ServiceConfig::log_level), .option = "-l,--log-level", .check = check_log_level},
      {.path = "role",
       .doc = "active: serves the cell; standby: watches its buses and its active service, sends "
              "nothing, and takes over when that one dies (or takes a cell nobody served for "
              "30 s); auto: serves if nobody serves the name, else stands by "
              "(docs/hot-standby.md)",
       .field = of_config(&ServiceConfig::role), .option = "--role", .check = check_role},
      {.path = "allow_admin", .type = boolean,
       .doc = "accept SET_CAN_ID and SET_BAUD_RATE (from anyone; under DDS Security from admin "
              "identities)",
       .field = of_config(&ServiceConfig::allow_admin), .option = "--allow-admin"},
      {.path = "client_rate_limit", .type = integer, .max = 1000000,
       .doc = "requests a second each client may send, in bursts of as many (a group request is "
              "one); more are answered BUSY; 0: no limit",
       .field = of_config(&ServiceConfig::client_rate_limit)},
      {.path = "metrics",
       .doc = "serve Prometheus /metrics on HOST:PORT (port 0: any free port); absent: off",
       .field = of_config(&ServiceConfig::metrics_address), .option = "--metrics",
       .check = check_metrics_address},
      {.path = "dds", .type = map, .doc = "the DDS participant"},
      {.path = "buses", .type = list,
       .doc = "the buses and their hands; a file without them needs --bus",
       .field = entered([](ConfigTarget& t) { t.bus = &t.config->buses.emplace_back(); }),
       .option = "-b,--bus", .note = "none (no file and no --bus: sim:1,2,3 as bus0)"},

      {.path = "dds.interfaces", .type = list,
       .doc = "IPv4 addresses of the NICs DDS uses, or [\"*\"] for all",
       .field = of_participant(&P::interfaces), .option = contract::kInterfaceOption, .note = "loopback only",
       .check = contract::check_interface},
      {.path = "dds.udp_only", .type = boolean,
       .doc = "UDP only (kept for older files; it is the default)",
       .field = of_participant(&P::udp_only), .option = contract::kUdpOnlyOption, .note = "true"},
      {.path = "dds.shared_memory", .type = boolean,
       .doc = "also Fast DDS's shared memory (contradicts udp_only: true)",
       .field = of_participant(&P::shared_memory), .option = contract::kSharedMemoryOption},
      {.path = "dds.discovery_servers", .type = list,
       .doc = "HOST[:PORT] of each discovery server, the n-th is `fastdds discovery -i n`; absent: "
              "ROS_DISCOVERY_SERVER, else multicast",
       .field = of_participant(&P::discovery_servers), .option = contract::kDiscoveryServerOption,
       .check = contract::check_discovery_server},
      {.path = "dds.xml_profile_file", .doc = "a Fast DDS XML file with the participant's QoS",
       .field = of_participant(&P::xml_profile_file), .option = contract::kXmlOption,
       .check = [](std::string_view path) {
         return contract::check_readable_file("XML profiles file", std::string(path));
       }},
      {.path = "dds.xml_profile",
       .doc = "the participant profile in that file (absent: its default profile)",
       .field = of_participant(&P::xml_profile), .option = contract::kProfileOption,
       .check = not_empty("the profile name")},
      {.path = "dds.status_refresh_ms", .type = milliseconds, .max = kDay,
       .doc = "a hand's status that only was read again goes out at most this often (any change "
              "at once); 0: after every read",
       .field = of_config(&ServiceConfig::status_refresh)},
      {.path = "dds.security", .type = map,
       .doc = "DDS Security (PKI-DH, Access-Permissions, AES-GCM-GMAC); absent: none"},
      {.path = "dds.security.dir",
       .doc = "the credentials, laid out as deploy/security/make-test-pki.sh writes them",
       .field = of_participant(&P::security_dir), .option = contract::kSecurityDirOption, .required = true,
       .check = not_empty("the security directory")},
      {.path = "dds.security.identity", .doc = "the sub-directory with this participant's credentials",
       .field = of_participant(&P::security_identity), .option = contract::kSecurityIdentityOption,
       .check = contract::check_identity},
  };
}

std::vector<ConfigKey> declare_bus() {
  using S = hand::SchedulerOptions;
  return {
      {.path = "buses[].name", .doc = "the bus's name in hand addresses (1-64 characters)",
       .field = of_bus(&BusSettings::name), .note = "the SocketCAN interface, else bus0, bus1, ...",
       .check = named("bus name")},
      {.path = "buses[].spec", .doc = "sim, sim:1,2,3, socketcan:IFACE, tcp:HOST:PORT or serial:PATH@BAUD",
       .field = of_bus(&BusSettings::spec), .required = true, .check = check_spec},
      {.path = "buses[].hands", .type = list, .doc = "the hands on the bus; empty or absent: discover them",
       .field = entered([](ConfigTarget& t) { t.hand = &t.bus->hands.emplace_back(); }),
       .note = "discover them"},
      {.path = "buses[].sim", .type = map,
       .doc = "how the simulated hands of a sim bus behave (sim buses only)"},
      {.path = "buses[].bit_rate", .type = integer, .max = kMaxBitRate,
       .doc = "the CAN line's bit rate behind the bus, if known (load figures, line budget); 0: unknown",
       .field = of_bus(&BusSettings::bit_rate)},
      {.path = "buses[].command_interval_ms", .type = milliseconds, .max = kDay,
       .doc = "the least time between two frames to one hand (the protocol's interval)",
       .field = of_scheduler(&S::command_interval)},
      {.path = "buses[].interval_margin_ms", .type = milliseconds, .max = kDay,
       .doc = "added to the interval where the path can shorten gaps (TCP, serial)",
       .field = of_bus(&BusSettings::interval_margin), .note = "2 on a transfer box, else 0"},
      {.path = "buses[].poll_interval_watch_ms", .type = milliseconds, .min = 1, .max = kDay,
       .doc = "the grip status of fingers that move or hold, the rotation status while rotating "
              "(then nothing else is polled)",
       .field = of_scheduler(&S::poll_interval_watch)},
      {.path = "buses[].poll_interval_moving_ms", .type = milliseconds, .min = 1, .max = kDay,
       .doc = "the registers of an initializing hand", .field = of_scheduler(&S::poll_interval_moving)},
      {.path = "buses[].poll_interval_position_moving_ms", .type = milliseconds, .max = kDay,
       .doc = "the position of fingers that move, the rotation while rotating, so statuses show "
              "the motion; 0: only once it ended (each read delays an event due in its frame by one frame)",
       .field = of_scheduler(&S::poll_interval_position_moving)},
      {.path = "buses[].poll_interval_idle_ms", .type = milliseconds, .min = 1, .max = kDay,
       .doc = "every register of a hand at rest that holds nothing",
       .field = of_scheduler(&S::poll_interval_idle)},
      {.path = "buses[].reply_timeout_ms", .type = milliseconds, .min = 1, .max = kDay,
       .doc = "how long a request waits for the hand's reply before a retry",
       .field = of_scheduler(&S::reply_timeout)},
      {.path = "buses[].admin_reply_timeout_ms", .type = milliseconds, .min = 1, .max = kDay,
       .doc = "the same for CAN ID and baud-rate writes (the hand stores them first)",
       .field = of_scheduler(&S::admin_reply_timeout)},
      {.path = "buses[].max_retries", .type = integer, .max = 100,
       .doc = "retries of a request that got no reply", .field = of_scheduler(&S::max_retries)},
      {.path = "buses[].offline_after_timeouts", .type = integer, .min = 1, .max = 1000,
       .doc = "requests in a row without a reply before the hand is offline",
       .field = of_scheduler(&S::offline_after_timeouts)},
      {.path = "buses[].offline_probe_interval_ms", .type = milliseconds, .min = 1, .max = kDay,
       .doc = "how often an offline hand is probed", .field = of_scheduler(&S::offline_probe_interval)},
      {.path = "buses[].init_timeout_ms", .type = milliseconds, .min = 1, .max = kDay,
       .doc = "how long an initialization may take", .field = of_scheduler(&S::init_timeout)},
      {.path = "buses[].motion_timeout_ms", .type = milliseconds, .min = 1, .max = kDay,
       .doc = "how long a motion may take", .field = of_scheduler(&S::motion_timeout)},
      {.path = "buses[].queue_capacity", .type = integer, .min = 1, .max = 100000,
       .doc = "commands waiting per hand; more are refused as BUSY",
       .field = of_scheduler(&S::queue_capacity)},
      {.path = "buses[].discovery_interval_ms", .type = milliseconds, .max = kDay,
       .doc = "how often a bus without listed hands scans for new ones; 0: never again",
       .field = of_scheduler(&S::discovery_interval)},
      {.path = "buses[].probe_spacing_ms", .type = milliseconds, .max = kDay,
       .doc = "the gap between two probes of a scan", .field = of_scheduler(&S::probe_spacing)},
      {.path = "buses[].record", .type = map,
       .doc = "the flight recorder: every frame sent and received, candump log format "
              "(docs/user-guide.md, \"Flight recorder and replay\"); absent: off",
       .field = entered([](ConfigTarget& t) { t.bus->record.emplace(); })},
  };
}

std::vector<ConfigKey> declare_sim_record_and_hands() {
  using R = bus::RecorderOptions;
  return {
      {.path = "buses[].sim.reply_delay_ms", .type = milliseconds, .max = kDay,
       .doc = "how long a simulated hand takes to reply", .field = of_sim(&SimSettings::reply_delay)},
      {.path = "buses[].sim.position_speed", .type = number, .min = 0.001, .max = 1e6,
       .doc = "finger speed, percent of the stroke per second",
       .field = of_sim(&SimSettings::position_speed)},
      {.path = "buses[].sim.rotation_speed", .type = number, .min = 0.001, .max = 1e6,
       .doc = "rotation speed, percent of 90 degrees per second",
       .field = of_sim(&SimSettings::rotation_speed)},
      {.path = "buses[].sim.init_time_ms", .type = milliseconds, .max = kDay,
       .doc = "how long a simulated initialization takes", .field = of_sim(&SimSettings::init_time)},
      {.path = "buses[].sim.bit_rate", .type = integer, .max = kMaxBitRate,
       .doc = "the simulated line's bit rate; 0: frames take no line time",
       .field = of_sim(&SimSettings::bit_rate)},

      {.path = "buses[].record.dir",
       .doc = "the directory of the files BUS.000001.log, ... (created if missing)",
       .field = of_record(&R::dir), .option = "--record", .required = true,
       .check = not_empty("the directory")},
      {.path = "buses[].record.max_file_bytes", .type = integer, .min = 4096, .max = 1099511627776.0,
       .doc = "a file's size before the next one starts", .field = of_record(&R::max_file_bytes)},
      {.path = "buses[].record.max_files", .type = integer, .min = 1, .max = 100000,
       .doc = "files kept; then the oldest is deleted", .field = of_record(&R::max_files)},

      {.path = "buses[].hands[].id", .type = integer, .min = 1, .max = 255,
       .doc = "the hand's CAN ID, once per bus", .field = of_hand(&HandSettings::id), .required = true},
      {.path = "buses[].hands[].name", .doc = "a name for the hand (0-64 characters)",
       .field = of_hand(&HandSettings::name),
       .check = [](std::string_view name) -> Checked {
         return name.empty() ? Checked{} : check_name("hand name", name);
       }},
      {.path = "buses[].hands[].object", .type = integer, .max = 100,
       .doc = "simulated hands only: an object between the fingers at this position",
       .field = of_hand(&HandSettings::object)},
      {.path = "buses[].hands[].rotation_obstacle", .type = integer, .max = 100,
       .doc = "simulated hands only: an obstacle that blocks the rotation here",
       .field = of_hand(&HandSettings::rotation_obstacle)},
  };
}

/// The defaults as the table shows them: each field read from default-made
/// option structs.
void fill_fallbacks(std::vector<ConfigKey>& keys) {
  ServiceConfig config;
  BusSettings bus;
  bus.record.emplace();
  HandSettings hand;
  ConfigTarget defaults{&config, &bus, &hand};
  for (ConfigKey& key : keys) {
    if (!key.note.empty()) {
      key.fallback = key.note;
    } else if (key.required) {
      key.fallback = "required";
    } else if (key.field.shown) {
      key.fallback = key.field.shown(defaults);
    }
  }
}

const std::vector<ConfigKey>& all_keys() {
  static const std::vector<ConfigKey> keys = [] {
    std::vector<ConfigKey> declared = declare_root_and_dds();
    for (auto part : {declare_bus(), declare_sim_record_and_hands()}) {
      std::move(part.begin(), part.end(), std::back_inserter(declared));
    }
    fill_fallbacks(declared);
    return declared;
  }();
  return keys;
}

std::string_view parent_of(std::string_view path) {
  const auto dot = path.rfind('.');
  return dot == std::string_view::npos ? std::string_view{} : path.substr(0, dot);
}

bool has_range(const ConfigKey& key) {
  return key.type == integer || key.type == milliseconds || key.type == number;
}

std::string range_text(const ConfigKey& key) {
  return number_text(key.min) + "-" + number_text(key.max);
}

/// The option's long name: "--domain" of "-d,--domain".
std::string_view long_option(std::string_view option) {
  const auto comma = option.rfind(',');
  return comma == std::string_view::npos ? option : option.substr(comma + 1);
}

}  // namespace

std::string_view to_string(KeyType type) {
  switch (type) {
    case text:
      return "text";
    case integer:
      return "integer";
    case milliseconds:
      return "milliseconds";
    case number:
      return "number";
    case boolean:
      return "boolean";
    case list:
      return "list";
    case map:
      return "map";
  }
  return "invalid KeyType";
}

std::span<const ConfigKey> config_keys() {
  return all_keys();
}

const ConfigKey* find_config_key(std::string_view path) {
  for (const ConfigKey& key : all_keys()) {
    if (key.path == path) return &key;
  }
  return nullptr;
}

std::vector<std::string_view> child_keys(std::string_view parent) {
  std::vector<std::string_view> names;
  for (const ConfigKey& key : all_keys()) {
    if (parent_of(key.path) != parent) continue;
    names.push_back(parent.empty() ? key.path : key.path.substr(parent.size() + 1));
  }
  return names;
}

std::string config_keys_table() {
  std::string table =
      "| key | option | type | default | range | what it sets |\n"
      "|---|---|---|---|---|---|\n";
  for (const ConfigKey& key : all_keys()) {
    const auto option = long_option(key.option);
    table += "| `" + std::string(key.path) + "` | " +
             (option.empty() ? std::string("-") : "`" + std::string(option) + "`") + " | " +
             std::string(to_string(key.type)) + " | " +
             (key.fallback.empty() ? std::string("-") : key.fallback) + " | " +
             (has_range(key) ? range_text(key) : "-") + " | " + std::string(key.doc) + " |\n";
  }
  return table;
}

std::string option_help(std::string_view path) {
  const ConfigKey* key = find_config_key(path);
  if (key == nullptr) return {};
  std::string help = std::string(key->doc) + " (key " + std::string(key->path);
  if (has_range(*key)) help += ", " + range_text(*key);
  if (!key->fallback.empty() && !key->required) help += ", default " + key->fallback;
  return help + ")";
}

std::string option_name(const ConfigKey& key) {
  return std::string(long_option(key.option));
}

Checked check_value(const ConfigKey& key, const ConfigValue& value) {
  if (const auto* integral = std::get_if<long long>(&value)) {
    if (*integral < key.min || *integral > key.max) {
      return fail(std::to_string(*integral) + " is out of range (" + range_text(key) + ")");
    }
  } else if (const auto* real = std::get_if<double>(&value)) {
    if (!(*real >= key.min && *real <= key.max)) {
      return fail(number_text(*real) + " is out of range (" + range_text(key) + ")");
    }
  } else if (const auto* text = std::get_if<std::string>(&value); text && key.check) {
    return key.check(*text);
  } else if (const auto* items = std::get_if<std::vector<std::string>>(&value); items && key.check) {
    for (const auto& item : *items) {
      if (auto checked = key.check(item); !checked) return checked;
    }
  }
  return {};
}

}  // namespace dh3::app
