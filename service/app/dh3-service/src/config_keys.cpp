#include "dh3/app/config_keys.hpp"

#include <array>
#include <cmath>
#include <cstdio>

namespace dh3::app {
namespace {

constexpr double kDay = 24.0 * 3600 * 1000;  // the longest time any key takes, in ms
constexpr double kMaxBitRate = 1'000'000;

using enum KeyType;

// Parents before their children; within a parent, the order the parser lists
// them in when it meets an unknown key.
constexpr std::array kKeys{
    ConfigKey{"name", text, "dh3", 0, 0, "service name; requests address hands by it (1-64 characters)"},
    ConfigKey{"domain", integer, "0", 0, 232, "DDS domain id (Fast DDS's default port mapping ends at 232)"},
    ConfigKey{"log_level", text, "info", 0, 0, "trace, debug, info, warn, error, critical or off"},
    ConfigKey{"allow_admin", boolean, "false", 0, 0, "accept SET_CAN_ID and SET_BAUD_RATE"},
    ConfigKey{"metrics", text, "", 0, 0, "serve Prometheus /metrics on HOST:PORT (port 0: any free port); absent: off"},
    ConfigKey{"dds", map, "", 0, 0, "the DDS participant"},
    ConfigKey{"buses", list, "sim:1,2,3 as bus0", 0, 0, "the buses and their hands"},

    ConfigKey{"dds.interfaces", list, "loopback only", 0, 0, "IPv4 addresses of the NICs DDS uses, or [\"*\"] for all"},
    ConfigKey{"dds.udp_only", boolean, "true", 0, 0, "UDP only (kept for older files; it is the default)"},
    ConfigKey{"dds.shared_memory", boolean, "false", 0, 0, "also Fast DDS's shared memory (contradicts udp_only: true)"},
    ConfigKey{"dds.discovery_servers", list, "", 0, 0, "HOST[:PORT] of each discovery server, the n-th is `fastdds discovery -i n`; absent: ROS_DISCOVERY_SERVER, else multicast"},
    ConfigKey{"dds.xml_profile_file", text, "", 0, 0, "a Fast DDS XML file with the participant's QoS"},
    ConfigKey{"dds.xml_profile", text, "", 0, 0, "the participant profile in that file (absent: its default profile)"},
    ConfigKey{"dds.status_refresh_ms", milliseconds, "5000", 0, kDay, "a hand's status that only was read again goes out at most this often (any change at once); 0: after every read"},
    ConfigKey{"dds.security", map, "", 0, 0, "DDS Security (PKI-DH, Access-Permissions, AES-GCM-GMAC); absent: none"},
    ConfigKey{"dds.security.dir", text, "", 0, 0, "the credentials, laid out as deploy/security/make-test-pki.sh writes them (required in dds.security)"},
    ConfigKey{"dds.security.identity", text, "service", 0, 0, "the sub-directory with this participant's credentials"},

    ConfigKey{"buses[].name", text, "the SocketCAN interface, else bus0, bus1, ...", 0, 0, "the bus's name in hand addresses (1-64 characters)"},
    ConfigKey{"buses[].spec", text, "", 0, 0, "required: sim, sim:1,2,3, socketcan:IFACE, tcp:HOST:PORT or serial:PATH@BAUD"},
    ConfigKey{"buses[].hands", list, "discover them", 0, 0, "the hands on the bus; empty or absent: discover them"},
    ConfigKey{"buses[].sim", map, "", 0, 0, "how the simulated hands of a sim bus behave (sim buses only)"},
    ConfigKey{"buses[].bit_rate", integer, "0", 0, kMaxBitRate, "the CAN line's bit rate behind the bus, if known (load figures, line budget); 0: unknown"},
    ConfigKey{"buses[].command_interval_ms", milliseconds, "20", 0, kDay, "the least time between two frames to one hand (the protocol's interval)"},
    ConfigKey{"buses[].interval_margin_ms", milliseconds, "2 on a transfer box, else 0", 0, kDay, "added to the interval where the path can shorten gaps (TCP, serial)"},
    ConfigKey{"buses[].poll_interval_watch_ms", milliseconds, "20", 1, kDay, "the grip status of fingers that move or hold, the rotation status while rotating (then nothing else is polled)"},
    ConfigKey{"buses[].poll_interval_moving_ms", milliseconds, "50", 1, kDay, "the registers of an initializing hand"},
    ConfigKey{"buses[].poll_interval_idle_ms", milliseconds, "500", 1, kDay, "every register of a hand at rest that holds nothing"},
    ConfigKey{"buses[].reply_timeout_ms", milliseconds, "150", 1, kDay, "how long a request waits for the hand's reply before a retry"},
    ConfigKey{"buses[].admin_reply_timeout_ms", milliseconds, "3000", 1, kDay, "the same for CAN ID and baud-rate writes (the hand stores them first)"},
    ConfigKey{"buses[].max_retries", integer, "2", 0, 100, "retries of a request that got no reply"},
    ConfigKey{"buses[].offline_after_timeouts", integer, "3", 1, 1000, "requests in a row without a reply before the hand is offline"},
    ConfigKey{"buses[].offline_probe_interval_ms", milliseconds, "1000", 1, kDay, "how often an offline hand is probed"},
    ConfigKey{"buses[].init_timeout_ms", milliseconds, "15000", 1, kDay, "how long an initialization may take"},
    ConfigKey{"buses[].motion_timeout_ms", milliseconds, "10000", 1, kDay, "how long a motion may take"},
    ConfigKey{"buses[].queue_capacity", integer, "16", 1, 100000, "commands waiting per hand; more are refused as BUSY"},
    ConfigKey{"buses[].discovery_interval_ms", milliseconds, "30000", 0, kDay, "how often a bus without listed hands scans for new ones; 0: never again"},
    ConfigKey{"buses[].probe_spacing_ms", milliseconds, "1", 0, kDay, "the gap between two probes of a scan"},

    ConfigKey{"buses[].record", map, "", 0, 0, "the flight recorder: every frame sent and received, candump log format (docs/user-guide.md, \"Flight recorder and replay\"); absent: off"},

    ConfigKey{"buses[].sim.reply_delay_ms", milliseconds, "2", 0, kDay, "how long a simulated hand takes to reply"},
    ConfigKey{"buses[].sim.position_speed", number, "200", 0.001, 1e6, "finger speed, percent of the stroke per second"},
    ConfigKey{"buses[].sim.rotation_speed", number, "200", 0.001, 1e6, "rotation speed, percent of 90 degrees per second"},
    ConfigKey{"buses[].sim.init_time_ms", milliseconds, "300", 0, kDay, "how long a simulated initialization takes"},
    ConfigKey{"buses[].sim.bit_rate", integer, "0", 0, kMaxBitRate, "the simulated line's bit rate; 0: frames take no line time"},

    ConfigKey{"buses[].record.dir", text, "", 0, 0, "required in record: the directory of the files BUS.000001.log, ... (created if missing)"},
    ConfigKey{"buses[].record.max_file_bytes", integer, "67108864", 4096, 1099511627776.0, "a file's size before the next one starts"},
    ConfigKey{"buses[].record.max_files", integer, "10", 1, 100000, "files kept; then the oldest is deleted"},

    ConfigKey{"buses[].hands[].id", integer, "", 1, 255, "required: the hand's CAN ID, once per bus"},
    ConfigKey{"buses[].hands[].name", text, "", 0, 0, "a name for the hand (1-64 characters)"},
    ConfigKey{"buses[].hands[].object", integer, "", 0, 100, "simulated hands only: an object between the fingers at this position"},
    ConfigKey{"buses[].hands[].rotation_obstacle", integer, "", 0, 100, "simulated hands only: an obstacle that blocks the rotation here"},
};

std::string_view parent_of(std::string_view path) {
  const auto dot = path.rfind('.');
  return dot == std::string_view::npos ? std::string_view{} : path.substr(0, dot);
}

std::string number_text(double value) {
  char text[32];
  if (value == std::floor(value)) {
    std::snprintf(text, sizeof text, "%.0f", value);
  } else {
    std::snprintf(text, sizeof text, "%g", value);
  }
  return text;
}

bool has_range(const ConfigKey& key) {
  return key.type == integer || key.type == milliseconds || key.type == number;
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
  return kKeys;
}

const ConfigKey* find_config_key(std::string_view path) {
  for (const ConfigKey& key : kKeys) {
    if (key.path == path) return &key;
  }
  return nullptr;
}

std::vector<std::string_view> child_keys(std::string_view parent) {
  std::vector<std::string_view> names;
  for (const ConfigKey& key : kKeys) {
    if (parent_of(key.path) != parent) continue;
    names.push_back(parent.empty() ? key.path : key.path.substr(parent.size() + 1));
  }
  return names;
}

std::string config_keys_table() {
  std::string table =
      "| key | type | default | range | what it sets |\n"
      "|---|---|---|---|---|\n";
  for (const ConfigKey& key : kKeys) {
    table += "| `" + std::string(key.path) + "` | " + std::string(to_string(key.type)) + " | " +
             (key.fallback.empty() ? std::string("-") : std::string(key.fallback)) + " | " +
             (has_range(key) ? number_text(key.min) + "-" + number_text(key.max) : "-") + " | " +
             std::string(key.doc) + " |\n";
  }
  return table;
}

}  // namespace dh3::app
