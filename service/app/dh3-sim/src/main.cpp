// dh3-sim: simulated DH-3 hands served as the vendor's transfer box over TCP,
// so dh3-service (bus "tcp:HOST:PORT") or any client of the box runs without
// hardware, or (--can IFACE) as nodes on a SocketCAN interface such as vcan0
// (bus "socketcan:IFACE"). Prints "listening HOST:PORT" or "serving N hands on
// IFACE" on stdout once ready; logs go to stderr; control commands come on
// stdin (see --help). With --min-interval-ms it prints "interval violations: N"
// on stdout as its last line.

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "dh3/bus/can_socket.hpp"
#include "dh3/base/clock.hpp"
#include "dh3/base/hand_ids.hpp"
#include "dh3/base/host_port.hpp"
#include "dh3/sim_server/can_server.hpp"
#include "dh3/sim_server/transfer_box_server.hpp"

namespace {

using dh3::sim::SimHandOptions;

// The one place with global state: a signal handler can reach nothing else.
// One of the two is set, for the transport in use.
std::atomic<dh3::sim::TransferBoxServer*> g_box_server{nullptr};
std::atomic<dh3::sim::CanServer*> g_can_server{nullptr};

extern "C" void on_stop_signal(int /*signal*/) {
  if (dh3::sim::TransferBoxServer* server = g_box_server.load()) server->request_stop();
  if (dh3::sim::CanServer* server = g_can_server.load()) server->request_stop();
}

void install_stop_handlers() {
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;  // no SA_RESTART: poll() returns EINTR at once
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  std::signal(SIGPIPE, SIG_IGN);
}

int parse_int(const std::string& text, const std::string& what) {
  std::size_t used = 0;
  int value = 0;
  try {
    value = std::stoi(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size())
    throw CLI::ValidationError(what, "'" + text + "' is no number");
  return value;
}

std::uint8_t parse_hand_id(const std::string& text, const std::string& what) {
  auto id = dh3::parse_hand_id(text);
  if (!id) throw CLI::ValidationError(what, id.error());
  return *id;
}

std::vector<std::uint8_t> parse_hand_list(const std::string& text) {
  auto ids = dh3::parse_hand_ids(text);
  if (!ids) throw CLI::ValidationError("--hands", ids.error());
  return *std::move(ids);
}

/// "ID:POS" with POS 0-100.
std::pair<std::uint8_t, std::int32_t> parse_placement(const std::string& text,
                                                      const std::string& what) {
  const std::size_t colon = text.find(':');
  if (colon == std::string::npos) throw CLI::ValidationError(what, "expected ID:POS, got " + text);
  const std::uint8_t id = parse_hand_id(text.substr(0, colon), what);
  const int position = parse_int(text.substr(colon + 1), what);
  if (position < 0 || position > 100) {
    throw CLI::ValidationError(what, "positions are 0-100, not " + text.substr(colon + 1));
  }
  return {id, position};
}

/// The recording --replay names; throws CLI::ValidationError saying what is wrong.
std::shared_ptr<const dh3::sim::ReplayScript> read_recording(const std::string& path) {
  std::ifstream file(path);
  std::ostringstream text;
  text << file.rdbuf();
  if (!file) throw CLI::ValidationError("--replay", "cannot read " + path);
  auto script = dh3::sim::ReplayScript::parse(text.str());
  if (!script) throw CLI::ValidationError("--replay", path + ": " + script.error());
  if (script->hands().empty()) {
    throw CLI::ValidationError("--replay", path + ": no hand answered in this recording");
  }
  return std::make_shared<const dh3::sim::ReplayScript>(std::move(*script));
}

/// Prints `ready_line` once a stop signal would reach `server`, runs it until
/// it stops, then prints the interval line if the interval is checked.
template <typename Server>
int serve(Server& server, std::atomic<Server*>& global, const std::string& ready_line,
          bool interval_checked) {
  global.store(&server);
  install_stop_handlers();
  std::printf("%s\n", ready_line.c_str());
  std::fflush(stdout);
  server.run();
  global.store(nullptr);
  if (interval_checked) {
    std::printf("interval violations: %llu\n",
                static_cast<unsigned long long>(server.interval_violations()));
    std::fflush(stdout);
  }
  return 0;
}

/// dh3-sim's command line.
struct SimArguments {
  std::string listen = "127.0.0.1:0";
  std::string can_interface;
  int min_interval_ms = 0;
  std::string hand_list = "1";
  std::vector<std::string> objects;
  std::vector<std::string> obstacles;
  int init_time_ms = 300;
  double speed = 200.0;
  double rotation_speed = 0.0;
  int reply_delay_ms = 0;
  int store_delay_ms = 50;
  std::string log_level = "info";
  std::string replay_file;
  bool shared = false;
};

void declare_options(CLI::App& app, SimArguments& args) {
  app.add_option("--listen", args.listen, "HOST:PORT to listen on (IPv4); port 0 picks a free one")
      ->capture_default_str();
  app.add_option("--can", args.can_interface,
                 "serve the hands on this SocketCAN interface (e.g. vcan0) instead of TCP")
      ->excludes("--listen");
  app.add_option(
         "--min-interval-ms", args.min_interval_ms,
         "log (stderr) every frame a hand receives sooner than MS after the previous frame to "
         "it, answer 'violations' with 'ok N', print 'interval violations: N' at exit. A frame "
         "to ID 0 counts for every hand. On CAN a frame's time is the kernel's receive "
         "timestamp; on TCP it is when dh3-sim read it (frames that arrive together count as "
         "sent together). 0: off")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--hands", args.hand_list, "CAN IDs of the simulated hands, e.g. 1,2,3 or 1-8")
      ->capture_default_str();
  app.add_option("--object", args.objects,
                 "ID:POS: an object between hand ID's fingers at POS (0-100)")
      ->take_all();
  app.add_option("--obstacle", args.obstacles,
                 "ID:POS: an obstacle blocking hand ID's rotation at POS")
      ->take_all();
  app.add_option("--init-time-ms", args.init_time_ms, "how long initialization takes")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--speed", args.speed, "finger speed, percent of the stroke per second")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--rotation-speed", args.rotation_speed,
                 "rotation speed, percent of 90 degrees per second (default: --speed)")
      ->check(CLI::PositiveNumber);
  app.add_option("--reply-delay-ms", args.reply_delay_ms, "time between a request and its reply")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--store-delay-ms", args.store_delay_ms,
                 "extra time before answering a CAN ID or baud rate write")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--replay", args.replay_file,
                 "serve the hands of a recording (dh3-service's flight recorder, one bus): each "
                 "request is answered with the reply recorded for its register, in the recorded "
                 "order, and unasked frames come at their recorded offsets")
      ->check(CLI::ExistingFile)
      ->excludes("--hands")
      ->excludes("--object")
      ->excludes("--obstacle");
  app.add_flag("--shared", args.shared,
               "TCP: every client receives every frame, the other clients' requests and every "
               "reply, as every node on a CAN bus does: a standby service watches the primary "
               "through it")
      ->excludes("--can");
  app.add_option("--log-level", args.log_level, "trace, debug, info, warn, error, critical, off")
      ->capture_default_str()
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));
  app.footer(std::string(dh3::sim::kControlHelp) +
             "\nSIGINT, SIGTERM or 'quit' stop it; end of stdin does not.");
}

/// The server's options from the parsed command line; throws
/// CLI::ValidationError naming the option that is wrong.
dh3::sim::TransferBoxServerOptions server_options(const SimArguments& args) {
  dh3::sim::TransferBoxServerOptions options;
  options.min_interval = std::chrono::milliseconds(args.min_interval_ms);
  dh3::HostPortRules listening;
  listening.port_zero = true;
  auto address = dh3::parse_host_port(args.listen, listening);
  if (!address) throw CLI::ValidationError("--listen", address.error() + " in " + args.listen);
  options.host = std::move(address->host);
  options.port = address->port;
  options.shared = args.shared;

  for (const std::uint8_t id : parse_hand_list(args.hand_list)) {
    SimHandOptions hand;
    hand.id = id;
    hand.init_time = std::chrono::milliseconds(args.init_time_ms);
    hand.position_speed = args.speed;
    hand.rotation_speed = args.rotation_speed > 0 ? args.rotation_speed : args.speed;
    hand.reply_delay = std::chrono::milliseconds(args.reply_delay_ms);
    hand.store_delay = std::chrono::milliseconds(args.store_delay_ms);
    options.hands.push_back(hand);
  }
  const auto find_hand = [&](std::uint8_t id, const std::string& what) -> SimHandOptions& {
    for (SimHandOptions& hand : options.hands) {
      if (hand.id == id) return hand;
    }
    throw CLI::ValidationError(what, "no hand " + std::to_string(id) + " in --hands");
  };
  for (const std::string& text : args.objects) {
    const auto [id, position] = parse_placement(text, "--object");
    find_hand(id, "--object").object_position = position;
  }
  for (const std::string& text : args.obstacles) {
    const auto [id, position] = parse_placement(text, "--obstacle");
    find_hand(id, "--obstacle").rotation_obstacle = position;
  }
  if (!args.replay_file.empty()) options.replay = read_recording(args.replay_file);
  return options;
}

int serve_on_can(const dh3::sim::TransferBoxServerOptions& options,
                 const std::string& can_interface, bool interval_checked) {
  dh3::sim::CanServerOptions can;
  static_cast<dh3::sim::SimHostOptions&>(can) = options;  // hands, control, interval
  can.interface_name = can_interface;
  // The same socket (and kernel filter for IDs 0-255) as dh3-service's socketcan bus.
  auto opened = dh3::sim::CanServer::open(
      can, [can_interface] { return dh3::bus::open_can_raw_socket(can_interface); },
      dh3::SystemClock::instance());
  if (!opened) {
    spdlog::critical("dh3-sim: cannot serve on {}: {}", can_interface, opened.error());
    return 1;
  }
  dh3::sim::CanServer& server = *opened.value();
  return serve(server, g_can_server,
               "serving " + std::to_string(server.hand_count()) + " hands on " + can_interface,
               interval_checked);
}

int serve_on_tcp(const dh3::sim::TransferBoxServerOptions& options, bool interval_checked) {
  auto opened = dh3::sim::TransferBoxServer::open(options, dh3::SystemClock::instance());
  if (!opened) {
    spdlog::critical("dh3-sim: cannot start: {}", dh3::sim::to_string(opened.error()));
    return 1;
  }
  dh3::sim::TransferBoxServer& server = *opened.value();
  return serve(server, g_box_server, "listening " + server.address(), interval_checked);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "dh3-sim: simulated DH-3 hands served as a transfer box over TCP (14-byte frames),\n"
      "or with --can as nodes on a SocketCAN interface (8-byte payloads, CAN ID = hand ID).\n"
      "Prints 'listening HOST:PORT' (TCP) or 'serving N hands on IFACE' (CAN) on stdout\n"
      "when ready; logs go to stderr."};
  SimArguments args;
  declare_options(app, args);
  dh3::sim::TransferBoxServerOptions options;
  try {
    app.parse(argc, argv);
    options = server_options(args);
  } catch (const CLI::ParseError& error) {
    return app.exit(error);
  }

  auto logger = spdlog::stderr_color_mt("dh3-sim");
  spdlog::set_default_logger(logger);
  spdlog::set_level(spdlog::level::from_str(args.log_level));

  if (options.replay) {
    std::string ids;
    for (const auto& [id, hand] : options.replay->hands()) ids += " " + std::to_string(id);
    spdlog::info("dh3-sim: replaying {} frames of bus '{}' ({} skipped); hands:{}",
                 options.replay->frames(), options.replay->device(), options.replay->skipped(),
                 ids);
  }
  options.control_in = 0;   // stdin
  options.control_out = 1;  // stdout
  const bool interval_checked = args.min_interval_ms > 0;
  if (!args.can_interface.empty()) {
    return serve_on_can(options, args.can_interface, interval_checked);
  }
  return serve_on_tcp(options, interval_checked);
}
