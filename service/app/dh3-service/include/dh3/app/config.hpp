#pragma once
// dh3-service's configuration: a YAML file (--config), command-line overrides,
// and the defaults that run it on the simulator with no configuration at all.
//
// The file; every key is optional except each bus's spec:
//
//   name: dh3                  # service name; requests address hands by it
//   domain: 0                  # DDS domain id, 0-232
//   log_level: info            # trace, debug, info, warn, error, critical, off
//   allow_admin: false         # accept SET_CAN_ID and SET_BAUD_RATE
//   metrics: 127.0.0.1:9464    # Prometheus /metrics on HOST:PORT (port 0: any); default off
//   dds:
//     interfaces: [127.0.0.1]  # IPv4 addresses of the NICs, or ["*"]; default loopback only
//     udp_only: true           # the default: UDP only (kept for older files)
//     shared_memory: false     # also Fast DDS shared memory (needs Fast DDS >= 2.12.1)
//     discovery_servers: [10.0.0.2:11811]  # HOST[:PORT]; n-th is `fastdds discovery -i n`
//     xml_profile_file: /etc/dh3/fastdds.xml  # participant QoS from a Fast DDS XML file
//     xml_profile: dh3_udp     # the participant profile in it (default: its default)
//     status_refresh_ms: 5000  # a hand's unchanged status (only read again) goes out at most
//                              # this often; any change at once (0: every idle read)
//     security:                # DDS Security (PKI-DH, Access-Permissions, AES-GCM-GMAC)
//       dir: /etc/dh3/pki      # laid out as deploy/security/make-test-pki.sh writes it
//       identity: service      # the sub-directory with this participant's credentials
//   buses:
//     - name: left             # default: the SocketCAN interface, else bus0, bus1, ...
//       spec: tcp:192.168.1.50:8888
//       command_interval_ms: 20   # and the other scheduler timings (BusSettings)
//       bit_rate: 1000000      # the CAN line's bit rate, if known (bus load, line budget)
//       hands:                 # empty or absent: discover the hands on the bus
//         - {id: 1, name: gripper}
//     - spec: sim              # simulated hands: the ones listed (or sim:IDS)
//       sim: {reply_delay_ms: 2, position_speed: 200, init_time_ms: 300}
//       hands:
//         - {id: 1, object: 40, rotation_obstacle: 70}   # sim only
//
// Bus specs: sim | sim:1,2,3 | socketcan:can0 | tcp:HOST:PORT | serial:PATH@BAUD.
// Scheduler keys per bus (milliseconds unless said): command_interval_ms, interval_margin_ms,
// poll_interval_watch_ms, poll_interval_moving_ms, poll_interval_idle_ms, reply_timeout_ms,
// admin_reply_timeout_ms, offline_probe_interval_ms, init_timeout_ms,
// motion_timeout_ms, discovery_interval_ms, probe_spacing_ms, max_retries,
// offline_after_timeouts, queue_capacity. Simulator keys (sim:): reply_delay_ms,
// position_speed, rotation_speed (percent per second), init_time_ms, bit_rate.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dh3/base/clock.hpp"
#include "dh3/base/result.hpp"
#include "dh3/hand/bus_scheduler.hpp"
#include "dh3_participant_options.hpp"

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

struct ServiceConfig {
  std::string name = "dh3";
  /// `domain` and the `dds` keys: domain, interfaces (empty: loopback only),
  /// udp_only or shared_memory, discovery servers (empty: ROS_DISCOVERY_SERVER if set, else
  /// multicast discovery), XML profile (empty: the project's participant
  /// QoS), DDS Security (empty directory: none; identity "service").
  contract::ParticipantOptions participant = service_participant();
  std::string log_level = "info";
  bool allow_admin = false;
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
