// dh3-service: puts the DH-3 hands of one or more buses on DDS.
//
// Exit codes: 0 after a clean stop (SIGINT, SIGTERM), 1 when the service cannot
// start (a bus cannot be opened, DDS cannot be set up), 2 for a configuration
// or command-line error, with a message that names the key (and the line).

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <csignal>
#include <cstdio>
#include <optional>
#include <string>

#include "dh3/app/bus_setup.hpp"
#include "dh3/app/config.hpp"
#include "dh3/app/config_keys.hpp"
#include "dh3/base/clock.hpp"
#include "dh3/dds/service.hpp"
#include "dh3/metrics/metrics_exporter.hpp"

#ifndef DH3_VERSION
#define DH3_VERSION "0.0.0"
#endif

namespace {

constexpr int kExitStartFailed = 1;
constexpr int kExitConfigError = 2;

std::string host_name() {
  char name[256] = {};
  if (gethostname(name, sizeof name - 1) != 0) return {};
  return name;
}

void set_up_logging(const std::string& level) {
  auto logger = spdlog::stderr_color_mt("dh3-service");
  logger->set_pattern("%Y-%m-%d %H:%M:%S.%e %^%l%$ %v");
  spdlog::set_default_logger(logger);
  spdlog::set_level(spdlog::level::from_str(level));
}

/// What the command line says and which config file it names.
struct Invocation {
  dh3::app::CommandLine line;
  std::string config_path;
};

/// The command line ends the program here (--help, --version, a usage error),
/// CLI11 having said why: the exit status.
struct EarlyExit {
  int status = 0;
};

/// -i, --udp-only, --shared-memory, --discovery-server: straight into `line`.
void add_transport_options(CLI::App& cli, dh3::app::CommandLine& line) {
  cli.add_option("-i,--interface", line.interfaces,
                 "IPv4 address of a network interface for DDS (repeatable), or * for all; "
                 "default loopback only")
      ->allow_extra_args(false);
  cli.add_flag("--udp-only", line.udp_only, "UDP only, no shared memory (the default)");
  cli.add_flag("--shared-memory", line.shared_memory,
               "also Fast DDS's shared-memory transport on this host (needs Fast DDS 2.12.1 or "
               "later: 2.9's listener can go deaf after a peer exits)");
  cli.add_option("--discovery-server", line.discovery_servers,
                 "a Fast DDS discovery server as HOST[:PORT] (repeatable; the n-th is the "
                 "server with id n; replaces the file's); default: ROS_DISCOVERY_SERVER if set")
      ->allow_extra_args(false);
}

/// What the command line asks for.
dh3::Result<Invocation, EarlyExit> parse_command_line(int argc, char** argv) {
  Invocation invocation;
  auto& line = invocation.line;
  auto& config_path = invocation.config_path;
  CLI::App cli{
      "dh3-service: DH-3 robot hands on DDS. With no config and no --bus it runs the "
      "simulator with hands 1, 2 and 3."};
  std::string name;
  std::string log_level;
  int domain = 0;
  cli.add_option("-c,--config", config_path, "YAML configuration file")->check(CLI::ExistingFile);
  cli.add_option("-b,--bus", line.buses,
                 "a bus as SPEC or NAME=SPEC (repeatable; replaces the file's buses): sim, "
                 "sim:1,2,3, socketcan:can0, tcp:HOST:PORT, serial:PATH@BAUD")
      ->allow_extra_args(false);  // one SPEC per --bus: a stray word is an error
  auto* name_option = cli.add_option("-n,--name", name, "service name (default dh3)");
  auto* domain_option = cli.add_option("-d,--domain", domain, "DDS domain id (default 0)");
  auto* level_option =
      cli.add_option("-l,--log-level", log_level,
                     "trace, debug, info, warn, error, critical or off (default info)");
  cli.add_flag("--allow-admin", line.allow_admin, "accept SET_CAN_ID and SET_BAUD_RATE");
  add_transport_options(cli, line);
  std::string xml_file;
  std::string xml_profile;
  std::string security_dir;
  std::string security_identity;
  auto* xml_option =
      cli.add_option("--xml", xml_file, "Fast DDS XML profiles file for the participant's QoS");
  auto* profile_option = cli.add_option(
      "--profile", xml_profile, "participant profile in the --xml file (default: its default)");
  auto* security_dir_option = cli.add_option(
      "--security-dir", security_dir,
      "enable DDS Security with the credentials in DIR (as deploy/security/make-test-pki.sh "
      "lays them out)");
  auto* security_identity_option =
      cli.add_option("--security-identity", security_identity,
                     "the identity (sub-directory of --security-dir) to use (default service)");
  std::string metrics_address;
  auto* metrics_option = cli.add_option(
      "--metrics", metrics_address,
      "serve Prometheus metrics at http://HOST:PORT/metrics (e.g. 127.0.0.1:9464; port 0 picks "
      "a free one, the log says which); empty turns the config file's off");
  bool print_config_keys = false;
  cli.add_flag("--config-keys", print_config_keys,
               "print every key of the configuration file (Markdown table) and exit");
  std::string record_dir;
  auto* record_option = cli.add_option(
      "--record", record_dir,
      "flight recorder: write every frame of every bus, with its time and direction, into DIR "
      "(candump log format, files BUS.000001.log, ...; a bus's record: settings keep their caps)");
  cli.set_version_flag("--version", DH3_VERSION);
  try {
    cli.parse(argc, argv);
  } catch (const CLI::Success& done) {
    return dh3::fail(EarlyExit{cli.exit(done)});
  } catch (const CLI::ParseError& error) {
    cli.exit(error);
    return dh3::fail(EarlyExit{kExitConfigError});
  }
  if (print_config_keys) {
    std::fputs(dh3::app::config_keys_table().c_str(), stdout);
    return dh3::fail(EarlyExit{0});
  }
  if (*name_option) line.name = name;
  if (*domain_option) line.domain = domain;
  if (*level_option) line.log_level = log_level;
  if (*xml_option) line.xml_profile_file = xml_file;
  if (*profile_option) line.xml_profile = xml_profile;
  if (*security_dir_option) line.security_dir = security_dir;
  if (*security_identity_option) line.security_identity = security_identity;
  if (*metrics_option) line.metrics_address = metrics_address;
  if (*record_option) line.record_dir = record_dir;
  return invocation;
}

/// The config file (or the built-in default) with the command line applied.
dh3::Result<dh3::app::ServiceConfig, dh3::app::ConfigError> load_configuration(
    const Invocation& invocation) {
  auto base =
      invocation.config_path.empty()
          ? dh3::Result<dh3::app::ServiceConfig, dh3::app::ConfigError>(dh3::app::default_config())
          : dh3::app::load_config(invocation.config_path);
  if (!base) return base;
  return dh3::app::apply_command_line(std::move(*base), invocation.line);
}

/// Opens the buses, starts the service (and the metrics exporter) and runs
/// until SIGINT or SIGTERM; the exit code.
int run_service(const dh3::app::ServiceConfig& config, const sigset_t& stop_signals) {
  set_up_logging(config.log_level);
  const dh3::Clock& clock = dh3::SystemClock::instance();
  auto buses = dh3::app::open_buses(config, clock);
  if (!buses) {
    spdlog::critical("{}", buses.error());
    return kExitStartFailed;
  }
  for (std::size_t i = 0; i < config.buses.size(); ++i) {
    spdlog::info("bus '{}': {}", config.buses[i].name, (*buses)[i].bus->spec());
  }

  dh3::dds::ServiceOptions options;
  options.name = config.name;
  options.participant = config.participant;
  options.allow_admin = config.allow_admin;
  options.status_refresh = config.status_refresh;
  options.version = DH3_VERSION;
  options.host = host_name();
  auto service = dh3::dds::Service::create(options, std::move(*buses), clock);
  if (!service) {
    spdlog::critical("{}", service.error());
    return kExitStartFailed;
  }
  std::unique_ptr<dh3::metrics::Exporter> exporter;
  if (!config.metrics_address.empty()) {
    auto started = dh3::metrics::Exporter::start(
        config.metrics_address, [&figures = **service] { return figures.metrics(); });
    if (!started) {
      spdlog::critical("{}", started.error());
      return kExitStartFailed;
    }
    exporter = std::move(*started);
    spdlog::info("metrics at http://{}/metrics", exporter->address());
  }
  if (auto started = (*service)->start(); !started) {
    spdlog::critical("{}", started.error());
    exporter.reset();
    service->reset();  // stops what did start: the buses, every hand published offline
    return kExitStartFailed;
  }

  int signal_number = 0;
  sigwait(&stop_signals, &signal_number);
  spdlog::info("{} received, stopping", signal_number == SIGINT ? "SIGINT" : "SIGTERM");
  exporter.reset();  // it reads the service's figures: gone before the service
  (*service)->stop();
  service->reset();
  spdlog::shutdown();
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  // Signals are taken by sigwait() below; every thread started later inherits
  // the blocked mask, so none of them is interrupted.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);

  const auto invocation = parse_command_line(argc, argv);
  if (!invocation) return invocation.error().status;
  const auto config = load_configuration(*invocation);
  if (!config) {
    std::fprintf(stderr, "dh3-service: config error: %s\n", config.error().message.c_str());
    return kExitConfigError;
  }
  return run_service(*config, stop_signals);
}
