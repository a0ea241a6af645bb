// Takeover (docs/hot-standby.md): how long after the active dh3-service is
// killed (SIGKILL) its standby serves the client, over several kills. Each
// run: dh3-sim's box with --shared and two hands, the active service and a
// standby on it, a client that initializes and moves hand 1; then the kill,
// at a random phase of the owner assertions. Measured at the client: the
// hand seen OFFLINE and then online again (the standby's statuses), and a
// read of its position answered by the standby after that. Also prints the
// takeover time the standby logs (from the loss it confirmed to serving),
// and when a read written at the kill ended (SERVICE_LOST with the lapse, or
// once the standby's claim arrives: docs/failover.md).
//
//   bench_takeover --kills 5

#include <CLI/CLI.hpp>
#include <csignal>
#include <mutex>
#include <random>
#include <thread>

#include "bench_util.hpp"
#include "dh3/client.hpp"
#include "dh3/registers.hpp"

namespace {

using dh3::bench::BenchClock;
using namespace std::chrono_literals;

std::string box_config(std::uint16_t port) {
  return "buses:\n"
         "  - name: bus0\n"
         "    spec: tcp:127.0.0.1:" +
         std::to_string(port) +
         "\n"
         "    hands:\n"
         "      - {id: 1}\n"
         "      - {id: 2}\n";
}

/// A dh3-service child with its log on stdout, read by the benchmark (the
/// active one's warnings only: nobody reads them).
dh3::test::Process service(const std::string& config, int domain, const std::string& name,
                           const std::string& role) {
  return dh3::test::Process(
      "/bin/sh",
      {"-c", "exec " + std::string(DH3_SERVICE_PATH) + " --config " + config + " --domain " +
                 std::to_string(domain) + " --name " + name + " --role " + role + " --log-level " +
                 (role == "standby" ? "info" : "warn") + " 2>&1"},
      dh3::test::Process::Stdin::dev_null);
}

/// Reads `process`'s output until a line holds `text`; that line.
std::optional<std::string> wait_for(dh3::test::Process& process, std::string_view text) {
  const auto deadline = BenchClock::now() + 30s;
  while (BenchClock::now() < deadline) {
    auto line = process.read_line(1000ms);
    if (line && line->find(text) != std::string::npos) return line;
  }
  return std::nullopt;
}

struct Takeover {
  double online_ms = 0;        ///< kill to the hand online again at the client
  double first_answer_ms = 0;  ///< kill to the first command after that answered
  double in_flight_ms = 0;     ///< kill to the end of a call written at the kill
  std::string in_flight;       ///< how that call ended
  std::string logged;          ///< the standby's "took over" line
};

std::optional<Takeover> one_kill(int domain, const std::string& name, std::mt19937& random) {
  dh3::test::Process sim(DH3_SIM_PATH, {"--listen", "127.0.0.1:0", "--hands", "1,2", "--shared",
                                        "--init-time-ms", "100", "--log-level", "warn"});
  const auto listening = sim.wait_for_line("listening ", 10s);
  if (!listening) return std::nullopt;
  const auto port =
      static_cast<std::uint16_t>(std::stoi(listening->substr(listening->rfind(':') + 1)));
  const dh3::bench::TempConfig config(box_config(port));
  auto active = service(config.path(), domain, name, "active");
  auto standby = service(config.path(), domain, name, "standby");
  if (!wait_for(standby, "is served by")) return std::nullopt;

  dh3::ClientOptions options;
  options.domain = domain;
  options.default_timeout = 30s;
  dh3::Client client(options);
  auto hand = client.wait_for_hand(name + "/bus0/1", 30s);
  if (!hand || !hand->initialize() || !hand->move_to(30)) return std::nullopt;
  std::this_thread::sleep_for(
      std::chrono::milliseconds(std::uniform_int_distribution<int>(300, 700)(random)));
  const auto killed = BenchClock::now();
  active.send_signal(SIGKILL);
  // A call written to the killed service: when and how it ends.
  std::optional<BenchClock::time_point> in_flight_ended;
  dh3::Reply in_flight;
  std::mutex in_flight_mutex;
  hand->read_async(dh3::reg::position, [&](const dh3::Reply& reply) {
    std::lock_guard lock(in_flight_mutex);
    in_flight = reply;
    in_flight_ended = BenchClock::now();
  });
  const auto online = [](const dh3::HandStatus& status) { return status.online; };
  if (!hand->wait_until([&](const dh3::HandStatus& status) { return !online(status); }, 30s) ||
      !hand->wait_until(online, 30s)) {
    return std::nullopt;
  }
  Takeover took;
  took.online_ms = dh3::bench::micros_between(killed, BenchClock::now()) / 1000.0;
  const dh3::Reply read = hand->read(dh3::reg::position);
  if (!read || read.value != 30) return std::nullopt;
  took.first_answer_ms = dh3::bench::micros_between(killed, BenchClock::now()) / 1000.0;
  for (int wait = 0; wait < 300; ++wait) {
    {
      std::lock_guard lock(in_flight_mutex);
      if (in_flight_ended) {
        took.in_flight_ms = dh3::bench::micros_between(killed, *in_flight_ended) / 1000.0;
        took.in_flight = in_flight.ok() ? "answered" : std::string(dh3::to_string(in_flight.code));
        break;
      }
    }
    std::this_thread::sleep_for(100ms);  // polling for the call's end, at most 30 s
  }
  if (auto line = wait_for(standby, "took over from")) took.logged = *line;
  standby.send_signal(SIGTERM);
  standby.wait_exit(20s);
  return took;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"bench_takeover: kill to the first command a standby answers"};
  int kills = 5;
  cli.add_option("--kills", kills, "how many takeovers");
  CLI11_PARSE(cli, argc, argv);
  const int domain = dh3::bench::bench_domain();
  std::mt19937 random(std::random_device{}());
  std::vector<double> online_ms;
  std::vector<double> ms;
  int missed = 0;
  for (int i = 0; i < kills; ++i) {
    const std::string name =
        "bench-takeover-" + std::to_string(::getpid()) + "-" + std::to_string(i);
    if (const auto took = one_kill(domain, name, random)) {
      online_ms.push_back(took->online_ms);
      ms.push_back(took->first_answer_ms);
      std::printf(
          "kill %2d: hand online again after %.0f ms, read answered after %.0f ms, read "
          "written at the kill ended %s after %.0f ms; standby: %s\n",
          i + 1, took->online_ms, took->first_answer_ms, took->in_flight.c_str(),
          took->in_flight_ms, took->logged.c_str());
    } else {
      ++missed;
      std::printf("kill %2d: the standby did not serve within 30 s\n", i + 1);
    }
    std::fflush(stdout);
  }
  const auto back = dh3::bench::percentiles(online_ms);
  const auto p = dh3::bench::percentiles(ms);
  std::printf(
      "takeover on dh3-sim's shared box, SIGKILL, %zu kills (%d missed): kill to hand "
      "online again p50 %.0f ms, max %.0f ms; kill to first command answered p50 %.0f "
      "ms, max %.0f ms\n",
      p.count, missed, back.p50, back.max, p.p50, p.max);
  return 0;
}
