#pragma once
// dh3-service's configuration: a YAML file (--config), command-line overrides,
// and the defaults that run it on the simulator with no configuration at all.
//
// Every key of the file, with its type, range, meaning and the field it
// fills, is declared in config_keys.cpp (`dh3-service --config-keys`, the
// docs/configuration.md's table); its default is the field's default member below. A file
// lists its buses (or --bus gives them); only with neither a file nor --bus
// does the service run the simulator (default_config()). A small file:
//
//   name: cell7
//   dds: {interfaces: [10.0.0.5]}
//   buses:
//     - {name: left, spec: "socketcan:can0", bit_rate: 1000000, hands: []}
//       record: {dir: /var/lib/dh3/recordings}   # the flight recorder
//     - spec: sim              # simulated hands: the ones listed (or sim:IDS)
//       hands: [{id: 1, object: 40}]

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dh3/base/clock.hpp"
#include "dh3/base/result.hpp"
#include "dh3/bus/frame_recorder.hpp"
#include "dh3/contract/participant_options.hpp"
#include "dh3/hand/bus_scheduler.hpp"

namespace dh3::app {

struct HandSettings {
  std::uint8_t id = 1;
  std::string name;
  /// Simulated hands only: an object between the fingers at this position.
  std::optional<std::int32_t> object;
  /// Simulated hands only: an obstacle that blocks rotation here.
  std::optional<std::int32_t> rotation_obstacle;
};

/// How the simulated hands of a sim bus behave. Defaults make the simulator
/// feel like a real hand: replies take a moment, motion takes visible time.
struct SimSettings {
  Duration reply_delay = std::chrono::milliseconds(2);
  double position_speed = 200.0;  ///< percent of the stroke per second
  double rotation_speed = 200.0;  ///< percent of 90 degrees per second
  Duration init_time = std::chrono::milliseconds(300);
  std::uint32_t bit_rate = 0;  ///< 0: frames take no line time
};

struct BusSettings {
  std::string name;
  std::string spec;
  /// The CAN line's bit rate behind a socketcan or transfer-box bus, when
  /// known: load figures, and the scheduler's line budget (max_line_load).
  /// 0: unknown. A sim bus takes sim.bit_rate instead.
  std::uint32_t bit_rate = 0;
  std::vector<HandSettings> hands;  ///< empty: discover
  hand::SchedulerOptions scheduler;
  /// interval_margin_ms; unset: default_interval_margin() of the bus's kind.
  std::optional<Duration> interval_margin;
  SimSettings sim;
  /// The flight recorder (`record:`, or --record DIR for every bus); nullopt: off.
  std::optional<bus::RecorderOptions> record;
};

/// 2 ms on a transfer box (TCP or serial: a frame the path delays shortens the
/// gap to the next as the hand sees it; measured up to 1 ms on loopback TCP),
/// 0 on SocketCAN (the kernel sends in order, measured on its timestamps) and sim.
[[nodiscard]] Duration default_interval_margin(std::string_view spec);

/// The service's participant before configuration: the test PKI's "service"
/// identity once a security directory is given.
inline contract::ParticipantOptions service_participant() {
  contract::ParticipantOptions participant;
  participant.security_identity = "service";
  return participant;
}

/// The values of the `role` key.
inline constexpr std::string_view kRoleActive = "active";
inline constexpr std::string_view kRoleStandby = "standby";
/// Either, decided at start: the two members of a pair run alike, and a
/// restarted one joins the other as its standby (docs/hot-standby.md).
inline constexpr std::string_view kRoleAuto = "auto";

struct ServiceConfig {
  std::string name = "dh3";
  /// `domain` and the `dds` keys: domain, interfaces (empty: loopback only),
  /// udp_only or shared_memory, discovery servers (empty: ROS_DISCOVERY_SERVER if set, else
  /// multicast discovery), XML profile (empty: the project's participant
  /// QoS), DDS Security (empty directory: none; identity "service").
  contract::ParticipantOptions participant = service_participant();
  std::string log_level = "info";
  /// kRoleActive, kRoleStandby or kRoleAuto (docs/hot-standby.md).
  std::string role{kRoleActive};
  bool allow_admin = false;
  /// dds::ServiceOptions::client_rate_limit.
  std::uint32_t client_rate_limit = 1000;
  /// dds.status_refresh_ms (dds::ServiceOptions::status_refresh).
  Duration status_refresh = std::chrono::seconds(5);
  /// Where /metrics is served ("IPv4:PORT" or "[IPv6]:PORT"); empty: not served.
  std::string metrics_address;
  std::vector<BusSettings> buses;
};

struct ConfigError {
  std::string message;  ///< names the key and, for the file, the line
};

/// The configuration with no file and no --bus: the simulator with hands 1, 2
/// and 3 on bus "bus0", service "dh3", domain 0.
[[nodiscard]] ServiceConfig default_config();

/// Parses a configuration file's text; `source` names it in messages
/// ("cell.yaml:12: buses[0].hands[1].id: 300 is out of range (1-255)").
[[nodiscard]] Result<ServiceConfig, ConfigError> parse_config(std::string_view yaml,
                                                              std::string_view source);
/// Reads and parses a configuration file.
[[nodiscard]] Result<ServiceConfig, ConfigError> load_config(const std::string& path);

/// What the command line may override. Unset fields leave the config alone.
struct CommandLine {
  std::optional<std::string> config_path;
  /// Each SPEC or NAME=SPEC; when given, they replace the file's buses.
  std::vector<std::string> buses;
  std::optional<std::string> name;
  std::optional<int> domain;
  std::optional<std::string> log_level;
  std::optional<std::string> role;
  bool allow_admin = false;
  std::vector<std::string> interfaces;         ///< replace the file's when given
  bool udp_only = false;                       ///< overrides the file's shared_memory
  bool shared_memory = false;                  ///< overrides the file's udp_only
  std::vector<std::string> discovery_servers;  ///< replace the file's when given
  std::optional<std::string> xml_profile_file;
  std::optional<std::string> xml_profile;
  std::optional<std::string> security_dir;
  std::optional<std::string> security_identity;
  std::optional<std::string> metrics_address;  ///< empty text turns the file's off
  /// Records every bus into this directory; a bus's own `record:` keeps its caps.
  std::optional<std::string> record_dir;
};

/// Applies the command line to a configuration and checks the result.
[[nodiscard]] Result<ServiceConfig, ConfigError> apply_command_line(ServiceConfig config,
                                                                    const CommandLine& line);

/// The name a bus from `--bus SPEC` gets: the SocketCAN interface's name, or
/// "bus<index>" for the others.
[[nodiscard]] std::string default_bus_name(std::string_view spec, std::size_t index);

/// Spec text that names only "sim": the hands listed in the bus are simulated.
[[nodiscard]] bool is_bare_sim_spec(std::string_view spec);

}  // namespace dh3::app
