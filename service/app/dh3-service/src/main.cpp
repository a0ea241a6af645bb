// dh3-service: puts the DH-3 hands of one or more buses on DDS.
//
// Exit codes: 0 after a clean stop (SIGINT, SIGTERM), 1 when the service cannot
// start (a bus cannot be opened, DDS cannot be set up), 2 for a configuration
// or command-line error, with a message that names the key (and the line).

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "dh3/app/bus_setup.hpp"
#include "dh3/app/config.hpp"
#include "dh3/app/config_keys.hpp"
#include "dh3/app/standby_watch.hpp"
#include "dh3/base/clock.hpp"
#include "dh3/base/host_name.hpp"
#include "dh3/base/stop_signals.hpp"
#include "dh3/base/version.hpp"
#include "dh3/bus/bus_spec.hpp"
#include "dh3/contract/ownership.hpp"
#include "dh3/contract/participant_flags.hpp"
#include "dh3/dds/service.hpp"
#include "dh3/dds/standby_presence.hpp"
#include "dh3/metrics/metrics_exporter.hpp"

namespace {

constexpr int kExitStartFailed = 1;
constexpr int kExitConfigError = 2;
/// Another service of the same name outranked this one (docs/failover.md).
constexpr int kExitLostOwnership = 3;

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

/// The option of the key at `path` as the keys' table declares it ("-d,--domain").
std::string option_of(std::string_view path) {
  return std::string(dh3::app::find_config_key(path)->option);
}

/// An option of a key: its name and help come from the keys' table, its
/// value goes to `target` (an optional: set only when given).
template <class T>
void add_key_option(CLI::App& cli, std::string_view path, std::optional<T>& target,
                    std::string_view detail = {}) {
  auto* option = cli.add_option_function<T>(
      option_of(path), [&target](const T& value) { target = value; },
      std::string(detail) + dh3::app::option_help(path));
  option->allow_extra_args(false);
}

/// The participant's options the command line gave, into `line`: the
/// service checks them as its configuration keys (config_keys.cpp), the
/// file's and the command line's values alike.
void take_participant_options(const dh3::contract::ParticipantOptionsGiven& given,
                              const dh3::contract::ParticipantOptions& values,
                              dh3::app::CommandLine& line) {
  if (given.domain->count() > 0) line.domain = values.domain;
  line.interfaces = values.interfaces;
  line.udp_only = values.udp_only;
  line.shared_memory = values.shared_memory;
  line.discovery_servers = values.discovery_servers;
  if (given.xml_profile_file->count() > 0) line.xml_profile_file = values.xml_profile_file;
  if (given.xml_profile->count() > 0) line.xml_profile = values.xml_profile;
  if (given.security_dir->count() > 0) line.security_dir = values.security_dir;
  if (given.security_identity->count() > 0) line.security_identity = values.security_identity;
}

/// What the command line asks for.
dh3::Result<Invocation, EarlyExit> parse_command_line(int argc, char** argv) {
  using dh3::app::option_help;
  Invocation invocation;
  auto& line = invocation.line;
  CLI::App cli{
      "dh3-service: DH-3 robot hands on DDS. With neither a config file nor --bus it runs the "
      "simulator with hands 1, 2 and 3; a config file lists its buses, or --bus gives them."};
  cli.add_option("-c,--config", invocation.config_path, "YAML configuration file")
      ->check(CLI::ExistingFile);
  // One SPEC per --bus: a stray word is an error.
  cli.add_option(option_of("buses"), line.buses,
                 "a bus as SPEC or NAME=SPEC (repeatable; replaces the file's buses): " +
                     option_help("buses[].spec"))
      ->allow_extra_args(false);
  add_key_option(cli, "name", line.name);
  add_key_option(cli, "log_level", line.log_level);
  add_key_option(cli, "role", line.role);
  cli.add_flag(option_of("allow_admin"), line.allow_admin, option_help("allow_admin"));
  dh3::contract::ParticipantOptions participant = dh3::app::service_participant();
  const auto given = dh3::contract::add_participant_options(
      cli, dh3::contract::fields_of(participant), dh3::contract::FlagChecks::by_caller);
  add_key_option(cli, "metrics", line.metrics_address,
                 "e.g. 127.0.0.1:9464, the log says the port; empty turns the file's off; ");
  bool print_config_keys = false;
  cli.add_flag("--config-keys", print_config_keys,
               "print every key of the configuration file (Markdown table) and exit");
  add_key_option(cli, "buses[].record.dir", line.record_dir,
                 "flight recorder of every bus (a bus's record: settings keep their caps): ");
  cli.set_version_flag("--version", dh3::kVersion);
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
  take_participant_options(given, participant, line);
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

/// What the service publishes and how it joins DDS, from the configuration.
dh3::dds::ServiceOptions service_options(const dh3::app::ServiceConfig& config) {
  dh3::dds::ServiceOptions options;
  options.name = config.name;
  options.participant = config.participant;
  options.allow_admin = config.allow_admin;
  options.client_rate_limit = config.client_rate_limit;
  options.status_refresh = config.status_refresh;
  options.version = dh3::kVersion;
  options.host = dh3::host_name();
  return options;
}

/// What a standby that takes over serves with: its presence on DDS, and what
/// to log once it serves.
struct Takeover {
  dh3::dds::StandbyPresence* standby = nullptr;
  std::function<void()> serving;
};

/// Creates the service on `buses` (on the standby's presence at a takeover),
/// starts it (and the metrics exporter) and runs until SIGINT or SIGTERM; the
/// exit code.
int serve(const dh3::app::ServiceConfig& config, dh3::dds::ServiceOptions options,
          std::vector<dh3::dds::BusSetup> buses, const sigset_t& stop_signals,
          const Takeover& takeover = {}) {
  const dh3::Clock& clock = dh3::SystemClock::instance();
  // Another service of this name outranks ours (docs/failover.md): stop, as
  // on SIGTERM, and exit non-zero.
  static std::atomic<bool> lost_ownership{false};
  options.on_lost_ownership = [](const std::string& /*why*/) {
    lost_ownership = true;
    ::kill(::getpid(), SIGTERM);
  };
  auto service =
      takeover.standby != nullptr
          ? dh3::dds::Service::take_over(options, std::move(buses), clock, *takeover.standby)
          : dh3::dds::Service::create(options, std::move(buses), clock);
  if (!service) {
    spdlog::critical("{}", service.error());
    return kExitStartFailed;
  }
  std::unique_ptr<dh3::metrics::Exporter> exporter;
  if (!config.metrics_address.empty()) {
    auto started = dh3::metrics::Exporter::start(
        config.metrics_address, [&figures = **service] { return figures.metrics(); },
        [&figures = **service] {
          const auto refused = figures.refusals();
          return dh3::metrics::RequestFigures{refused.busy_in_flight, refused.busy_rate,
                                              refused.held_replies_dropped};
        });
    if (!started) {
      spdlog::critical("{}", started.error());
      return kExitStartFailed;
    }
    exporter = std::move(*started);
    spdlog::info("metrics at http://{}/metrics", exporter->address());
    if (const auto warning = dh3::metrics::exposure_warning(config.metrics_address);
        !warning.empty()) {
      spdlog::warn("{}", warning);
    }
  }
  if (auto started = (*service)->start(); !started) {
    spdlog::critical("{}", started.error());
    exporter.reset();
    service->reset();  // stops what did start: the buses, every hand published offline
    return kExitStartFailed;
  }
  if (takeover.serving) takeover.serving();

  int signal_number = 0;
  sigwait(&stop_signals, &signal_number);
  if (lost_ownership) {
    spdlog::critical("another service of this name outranks this one: stopping");
  } else {
    spdlog::info("{} received, stopping", signal_number == SIGINT ? "SIGINT" : "SIGTERM");
  }
  exporter.reset();  // it reads the service's figures: gone before the service
  (*service)->stop();
  service->reset();
  spdlog::shutdown();
  return lost_ownership ? kExitLostOwnership : 0;
}

std::int64_t as_ms(dh3::Duration duration) {
  return std::chrono::duration_cast<std::chrono::milliseconds>(duration).count();
}

/// How long a standby's bus must carry no request before it counts as free:
/// the active service polls every listed hand at least every idle poll
/// interval, and this margin covers a frame's delay on the way.
constexpr dh3::Duration kFenceMargin = std::chrono::milliseconds(100);

dh3::Duration fence_quiet(const std::vector<dh3::dds::BusSetup>& buses) {
  dh3::Duration longest{};
  for (const auto& bus : buses) longest = std::max(longest, bus.scheduler.poll_interval_idle);
  return longest + kFenceMargin;
}

/// How many quiet times an active service watches a shared bus at most before
/// it gives up: a bus another service drives carries a request within one.
constexpr int kStartWatchQuietTimes = 2;
/// The longest quiet time it waits for at start: a cell whose idle poll is
/// slower (a minute, say) is not kept from serving that long; a master as
/// quiet as that is caught only if it sends meanwhile.
constexpr dh3::Duration kStartWatchLongest = std::chrono::seconds(2);

/// An active service's first look at its buses, once DDS showed it no other
/// service of its name (ServiceOptions::before_serving). It sends nothing until each
/// bus it may share with another service (a CAN interface, a transfer box;
/// not a bus simulated in this process) carried no request for the fence's
/// quiet time: a service of the cell that DDS did not show it (a network
/// partition, another domain or name, one that took the cell in the same
/// second) would otherwise get a second master on its bus, and the two
/// would complete on each other's echoes. The buses, promoted, ready to
/// serve; or why this service must not serve them.
dh3::Result<std::vector<dh3::dds::BusSetup>, std::string> watch_buses_first(
    std::vector<dh3::dds::BusSetup> buses) {
  const bool shared = std::any_of(buses.begin(), buses.end(), [](const auto& setup) {
    return !dh3::bus::is_simulated(setup.bus->spec());
  });
  if (!shared) return buses;
  const dh3::Clock& clock = dh3::SystemClock::instance();
  const dh3::Duration quiet = std::min(fence_quiet(buses), kStartWatchLongest);
  dh3::app::StandbyWatch watch(std::move(buses), quiet, clock);
  watch.start();
  spdlog::info("watching the buses {} ms for requests of another service before sending",
               as_ms(quiet));
  const dh3::TimePoint give_up = clock.now() + kStartWatchQuietTimes * quiet;
  for (;;) {
    const dh3::TimePoint now = clock.now();
    if (watch.fences_clear(now)) return watch.take_buses();
    if (now >= give_up) {
      std::string names;
      for (const auto& name : watch.busy_buses(now)) {
        names += (names.empty() ? "'" : ", '") + name + "'";
      }
      return dh3::fail(
          "bus " + names + " carries the requests of another service (" +
          std::to_string(watch.requests_seen()) + " seen in " +
          std::to_string(as_ms(kStartWatchQuietTimes * quiet)) +
          " ms) that DDS does not show as serving this cell (another DDS domain, another name, "
          "a network partition?): not serving, so that its hands do not get two masters");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));  // how soon a quiet bus is noticed
  }
}

/// Opens the buses and serves them; the exit code.
int run_service(const dh3::app::ServiceConfig& config, const sigset_t& stop_signals) {
  auto buses = dh3::app::open_buses(config, dh3::SystemClock::instance());
  if (!buses) {
    spdlog::critical("{}", buses.error());
    return kExitStartFailed;
  }
  for (std::size_t i = 0; i < config.buses.size(); ++i) {
    spdlog::info("bus '{}': {}", config.buses[i].name, (*buses)[i].bus->spec());
  }
  dh3::dds::ServiceOptions options = service_options(config);
  options.before_serving = watch_buses_first;
  return serve(config, std::move(options), std::move(*buses), stop_signals);
}

/// How long a cell may go unserved before a standby that saw no owner takes
/// it (docs/hot-standby.md). Role auto: the window a starting service listens
/// before it serves, so that it serves when nobody does and stands by when
/// somebody does. Role standby: long enough for the cell's configured active
/// service to come up first when its PC boots slower than the standby's.
dh3::Duration vacancy_wait(const dh3::app::ServiceConfig& config) {
  if (config.role == dh3::app::kRoleAuto) return dh3::contract::kStartClaimWindow;
  return std::chrono::seconds(30);
}

/// Why a standby that would take the cell does not: its fence holds.
std::string fenced(const dh3::dds::PrimaryLapse& lapse, const std::string& service) {
  if (!lapse.primary) {
    return "standby: no service of '" + service +
           "' was seen on DDS, but requests of a service are on the bus: not taking the cell "
           "while they go on";
  }
  return "standby: " + lapse.primary->describe() +
         " is gone from DDS, but its requests are still on the bus: not taking over while they "
         "go on";
}

/// Waits until the active service's loss stands (or the cell is vacant) and
/// every bus is quiet: that loss; nullopt when SIGINT or SIGTERM came first.
std::optional<dh3::dds::PrimaryLapse> wait_for_takeover(dh3::dds::StandbyPresence& presence,
                                                        const dh3::app::StandbyWatch& watch,
                                                        const std::string& service,
                                                        const sigset_t& stop_signals) {
  const dh3::Clock& clock = dh3::SystemClock::instance();
  const timespec poll{0, 10'000'000};  // how soon a lapse or a quiet bus is noticed
  bool fence_reported = false;
  while (sigtimedwait(&stop_signals, nullptr, &poll) < 0) {
    const dh3::TimePoint now = clock.now();
    const auto lapse = presence.lapse(now, watch.silent_at());
    if (!lapse) {
      fence_reported = false;
      continue;
    }
    if (watch.fences_clear(now)) return lapse;
    if (!fence_reported) {
      spdlog::warn("{}", fenced(*lapse, service));
      fence_reported = true;
    }
  }
  spdlog::info("standby stopping");
  return std::nullopt;
}

/// A standby: watches the buses and the active service, sends nothing, and
/// takes over when that one is gone and the buses are quiet; the exit code.
int run_standby(const dh3::app::ServiceConfig& config, const sigset_t& stop_signals) {
  const dh3::Clock& clock = dh3::SystemClock::instance();
  auto buses = dh3::app::open_buses(config, clock);
  if (!buses) {
    spdlog::critical("{}", buses.error());
    return kExitStartFailed;
  }
  dh3::dds::ServiceOptions options = service_options(config);
  const dh3::Duration quiet = fence_quiet(*buses);
  dh3::app::StandbyWatch watch(std::move(*buses), quiet, clock);
  watch.start();
  auto presence = dh3::dds::StandbyPresence::create(options, vacancy_wait(config));
  if (!presence) {
    spdlog::critical("{}", presence.error());
    return kExitStartFailed;
  }
  spdlog::info(
      "role {}: standby for service '{}' on {} bus(es): sending nothing, a bus counts as free "
      "after {} ms without a request; with no service of the name seen for {} ms it takes "
      "the cell",
      config.role, config.name, config.buses.size(), as_ms(quiet), as_ms(vacancy_wait(config)));
  const auto lapse = wait_for_takeover(**presence, watch, config.name, stop_signals);
  if (!lapse) return 0;

  const auto states = watch.states();
  auto setups = watch.take_buses();
  // A cell that nobody served: its hands are read afresh, as at any start.
  if (lapse->primary) {
    for (std::size_t i = 0; i < setups.size(); ++i) setups[i].warm = states[i];
  }
  options.epoch_floor = lapse->epoch + 1;
  const auto serving = [&lapse, &clock, epoch = options.epoch_floor] {
    if (!lapse->primary) {
      spdlog::warn(
          "took the cell: no service of its name was seen and its buses were quiet: serving "
          "with epoch {}",
          epoch);
      return;
    }
    spdlog::warn(
        "took over from {} (epoch {}): serving with epoch {}, {} ms after its loss was "
        "first seen",
        lapse->primary->describe(), lapse->primary->epoch, epoch,
        as_ms(clock.now() - lapse->since));
  };
  return serve(config, std::move(options), std::move(setups), stop_signals,
               Takeover{presence->get(), serving});
}

}  // namespace

int main(int argc, char** argv) {
  // Taken by sigwait() in serve() (sigtimedwait() while a standby waits).
  const sigset_t stop_signals = dh3::block_stop_signals();

  const auto invocation = parse_command_line(argc, argv);
  if (!invocation) return invocation.error().status;
  const auto config = load_configuration(*invocation);
  if (!config) {
    std::fprintf(stderr, "dh3-service: config error: %s\n", config.error().message.c_str());
    return kExitConfigError;
  }
  set_up_logging(config->log_level);
  return config->role == dh3::app::kRoleActive ? run_service(*config, stop_signals)
                                               : run_standby(*config, stop_signals);
}
