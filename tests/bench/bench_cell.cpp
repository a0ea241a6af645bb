// A cell of clients commanding one service at once (item 4).
//
// dh3-service (a child process) serves 16 simulated hands on one bus that
// answer at once (reply delay 0, command interval 0, status polling slowed to
// once a minute so its CPU is the commands'). 1, 4 and 16 client processes
// (dh3::Client each, one hand each) warm up, wait until all are ready, then
// each times `--count` READ_REGISTER commands, one in flight per client.
// Printed per client count:
//   - replies delivered to each client per command it sent: the replies that
//     reached the client process (its own, plus any other client's that DDS
//     delivered and the client dropped: Client::command_traffic()), divided by
//     the requests it wrote during the timed phase; the lowest and highest over
//     the clients (the goal is exactly 1),
//   - the service's CPU time (user + system, /proc/PID/stat) per command, and a
//     client process's per command it sent,
//   - p50, p90, p99 and max round trip over every client's commands.
//
//   bench_cell [--count N] [--clients 1,4,16] [--udp-only] [--service-binary PATH] [--json FILE]
//   bench_cell --role client --domain D --service NAME --hand ID --count N --out FILE
//              [--udp-only]                                           (internal)

#include <spdlog/spdlog.h>

#include <cinttypes>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "bench_util.hpp"
#include "dh3/client.hpp"
#include "dh3/registers.hpp"

namespace {

using namespace std::chrono_literals;
using namespace dh3;
using bench::BenchClock;

constexpr int kHands = 16;
constexpr int kWarmup = 200;
constexpr auto kReplyDeadline = 5s;

std::string service_config() {
  return "buses:\n"
         "  - name: bus0\n"
         "    spec: sim:" +
         bench::hand_ids(kHands) +
         "\n"
         "    command_interval_ms: 0\n"
         "    poll_interval_moving_ms: 60000\n"
         "    poll_interval_idle_ms: 60000\n"
         "    sim: {reply_delay_ms: 0}\n";
}

/// One client process: warms up, says "ready", waits for stdin to close, then
/// times `count` reads of its hand; writes the round trips (microseconds, one
/// a line) to `out` and prints "result WRITTEN OWN FOREIGN FAILED CPU_US" (its
/// own CPU time over the timed phase).
int run_client(int domain, const std::string& service, int hand_id, int count, bool udp_only,
               const std::string& out) {
  ClientOptions options;
  options.domain = domain;
  options.participant_name = "dh3-bench-cell-client";
  options.udp_only = udp_only;
  options.shared_memory = !udp_only;  // "shm": not the default
  Client client(options);
  auto hand = client.wait_for_hand(service + "/bus0/" + std::to_string(hand_id), 60s);
  if (!hand) {
    std::fprintf(stderr, "no hand: %s\n", hand.message().c_str());
    return 1;
  }
  for (int i = 0; i < kWarmup; ++i) (void)hand->read(reg::closing_force, kReplyDeadline);
  std::printf("ready\n");
  std::fflush(stdout);
  for (std::string line; std::getline(std::cin, line);) {
  }
  const CommandTraffic before = client.command_traffic();
  const double cpu_before = bench::cpu_seconds_of(::getpid());
  std::vector<double> micros;
  micros.reserve(static_cast<std::size_t>(count));
  int failed = 0;
  for (int i = 0; i < count; ++i) {
    const auto start = BenchClock::now();
    const Reply reply = hand->read(reg::closing_force, kReplyDeadline);
    const auto end = BenchClock::now();
    if (!reply) {
      ++failed;
      continue;
    }
    micros.push_back(bench::micros_between(start, end));
  }
  // Replies to other clients' last commands may still be on their way here.
  std::this_thread::sleep_for(200ms);
  const CommandTraffic after = client.command_traffic();
  const double cpu_us = 1e6 * (bench::cpu_seconds_of(::getpid()) - cpu_before);
  {
    std::ofstream file(out);
    for (const double m : micros) file << m << '\n';
  }
  std::printf("result %" PRIu64 " %" PRIu64 " %" PRIu64 " %d %.0f\n",
              after.requests_written - before.requests_written,
              after.own_replies - before.own_replies,
              after.foreign_replies - before.foreign_replies, failed, cpu_us);
  return 0;
}

struct ClientResult {
  std::uint64_t written = 0;
  std::uint64_t own = 0;
  std::uint64_t foreign = 0;
  int failed = 0;
  double cpu_us = 0;
  [[nodiscard]] double replies_per_command() const {
    return written == 0 ? 0 : static_cast<double>(own + foreign) / static_cast<double>(written);
  }
};

struct CellRow {
  int clients = 0;
  std::uint64_t commands = 0;
  double replies_min = 0;
  double replies_max = 0;
  std::uint64_t foreign = 0;
  int failed = 0;
  double service_cpu_us = 0;  ///< per command
  double client_cpu_us = 0;   ///< per command, over all clients
  bench::Percentiles latency;
  bool complete = false;
};

CellRow run_cell(int domain, int clients, int count, bool udp_only,
                 const std::string& service_binary) {
  CellRow row;
  row.clients = clients;
  bench::ServiceChild service(service_config(), domain, "cell", udp_only, service_binary);
  std::vector<std::unique_ptr<test::Process>> processes;
  std::vector<std::string> outs;
  for (int i = 0; i < clients; ++i) {
    outs.push_back("/tmp/dh3-bench-cell-" + std::to_string(::getpid()) + "-" + std::to_string(i));
    std::vector<std::string> args{"--role",    "client",
                                  "--domain",  std::to_string(domain),
                                  "--service", "cell",
                                  "--hand",    std::to_string(i + 1),
                                  "--count",   std::to_string(count),
                                  "--out",     outs.back()};
    if (udp_only) args.emplace_back("--udp-only");
    processes.push_back(std::make_unique<test::Process>(bench::self_path(), args));
  }
  for (auto& process : processes) {
    if (!process->wait_for_line("ready", 180s)) {
      std::fprintf(stderr, "a client of the %d-client cell never became ready\n", clients);
      return row;
    }
  }
  const double cpu_before = bench::cpu_seconds_of(service.pid());
  for (auto& process : processes) process->close_stdin();
  std::vector<ClientResult> results;
  for (auto& process : processes) {
    const auto line = process->wait_for_line("result", 600s);
    if (!line) {
      std::fprintf(stderr, "a client of the %d-client cell did not finish\n", clients);
      return row;
    }
    ClientResult result;
    std::istringstream fields(line->substr(7));
    fields >> result.written >> result.own >> result.foreign >> result.failed >> result.cpu_us;
    results.push_back(result);
  }
  const double cpu_after = bench::cpu_seconds_of(service.pid());
  for (auto& process : processes) process->wait_exit(20s);
  std::vector<double> micros;
  for (const auto& out : outs) {
    std::ifstream file(out);
    for (double m = 0; file >> m;) micros.push_back(m);
    std::remove(out.c_str());
  }
  row.replies_min = 1e9;
  double client_cpu_us = 0;
  for (const ClientResult& r : results) {
    client_cpu_us += r.cpu_us;
    row.commands += r.written;
    row.foreign += r.foreign;
    row.failed += r.failed;
    row.replies_min = std::min(row.replies_min, r.replies_per_command());
    row.replies_max = std::max(row.replies_max, r.replies_per_command());
  }
  row.service_cpu_us =
      row.commands == 0 ? 0 : 1e6 * (cpu_after - cpu_before) / static_cast<double>(row.commands);
  row.client_cpu_us = row.commands == 0 ? 0 : client_cpu_us / static_cast<double>(row.commands);
  row.latency = bench::percentiles(micros);
  row.complete = true;
  return row;
}

std::vector<int> parse_counts(const std::string& text) {
  std::vector<int> counts;
  std::istringstream in(text);
  for (std::string item; std::getline(in, item, ',');) {
    if (!item.empty()) counts.push_back(std::stoi(item));
  }
  return counts;
}

double load_average() {
  std::ifstream in("/proc/loadavg");
  double one_minute = 0;
  in >> one_minute;
  return one_minute;
}

int run_benchmark(int count, const std::string& client_counts, bool udp_only,
                  const std::string& service_binary, const std::string& json_path) {
  const int domain = bench::bench_domain();
  std::vector<CellRow> rows;
  for (const int clients : parse_counts(client_counts)) {
    if (clients < 1 || clients > kHands) {
      std::fprintf(stderr, "client counts are 1-%d\n", kHands);
      return 1;
    }
    rows.push_back(run_cell(domain, clients, count, udp_only, service_binary));
  }
  std::printf(
      "Cell: N client processes commanding one dh3-service at once (%s), %d reads each, one in "
      "flight per client; load average %.2f\n",
      udp_only ? "udp" : "shm", count, load_average());
  std::printf("%7s %8s %11s %11s %8s %7s %10s %11s %9s %9s %9s %9s\n", "clients", "commands",
              "replies/cmd", "(max)", "foreign", "failed", "svc cpu/cmd", "cli cpu/cmd", "p50",
              "p90", "p99", "max");
  for (const CellRow& r : rows) {
    if (!r.complete) {
      std::printf("%7d  (did not complete)\n", r.clients);
      continue;
    }
    std::printf(
        "%7d %8" PRIu64 " %11.3f %11.3f %8" PRIu64 " %7d %10.1f %11.1f %9.1f %9.1f %9.1f %9.1f\n",
        r.clients, r.commands, r.replies_min, r.replies_max, r.foreign, r.failed, r.service_cpu_us,
        r.client_cpu_us, r.latency.p50, r.latency.p90, r.latency.p99, r.latency.max);
  }
  std::printf(
      "(replies/cmd: replies that reached a client per request it wrote, lowest and highest over "
      "the clients; foreign: other clients' replies that reached them; svc cpu/cmd: dh3-service's "
      "user + system CPU microseconds per command; cli cpu/cmd: a client process's, per command it "
      "sent; round trips in microseconds over all clients)\n");
  if (rows.size() > 1 && rows.front().complete && rows.back().complete &&
      rows.front().service_cpu_us > 0) {
    std::printf("service CPU per command, %d clients / %d client%s: %.2f (goal: at most 1.2)\n",
                rows.back().clients, rows.front().clients, rows.front().clients == 1 ? "" : "s",
                rows.back().service_cpu_us / rows.front().service_cpu_us);
  }
  if (!json_path.empty()) {
    std::FILE* f = std::fopen(json_path.c_str(), "w");
    if (f == nullptr) {
      std::perror(json_path.c_str());
      return 1;
    }
    std::fprintf(f, "{\"benchmark\":\"cell\",\"transport\":\"%s\",\"count\":%d,\"rows\":[",
                 udp_only ? "udp" : "shm", count);
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const CellRow& r = rows[i];
      std::fprintf(f,
                   "%s{\"clients\":%d,\"complete\":%s,\"commands\":%" PRIu64
                   ",\"replies_per_command_min\":%.4f,\"replies_per_command_max\":%.4f,"
                   "\"foreign_replies\":%" PRIu64
                   ",\"failed\":%d,\"service_cpu_us_per_command\":%.2f,\"client_cpu_us_per_"
                   "command\":%.2f,\"latency\":%s}",
                   i == 0 ? "" : ",", r.clients, r.complete ? "true" : "false", r.commands,
                   r.replies_min, r.replies_max, r.foreign, r.failed, r.service_cpu_us,
                   r.client_cpu_us, bench::to_json(r.latency).c_str());
    }
    std::fprintf(f, "],\"load_average\":%.2f}\n", load_average());
    std::fclose(f);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"A cell of 1, 4 and 16 clients commanding one dh3-service at once"};
  bench::CommonOptions common;
  bench::add_common_options(app, common);
  int count = 2'000;
  std::string clients = "1,4,16";
  bool udp_only = false;
  int hand = 1;
  std::string out;
  std::string service_binary = DH3_SERVICE_PATH;
  app.add_option("--service-binary", service_binary,
                 "The dh3-service to run (another build, to compare)")
      ->capture_default_str();
  app.add_option("--count", count, "Timed commands per client")->capture_default_str();
  app.add_option("--clients", clients, "Client counts to run, comma-separated (1-16)")
      ->capture_default_str();
  app.add_flag("--udp-only", udp_only, "UDP only, no shared memory");
  app.add_option("--hand", hand, "(client role) the hand's CAN ID");
  app.add_option("--out", out, "(client role) where to write the round trips");
  CLI11_PARSE(app, argc, argv);
  auto& [json_path, role, domain, service] = common;
  spdlog::set_level(spdlog::level::warn);
  if (role == "client") return run_client(domain, service, hand, count, udp_only, out);
  return run_benchmark(count, clients, udp_only, service_binary, json_path);
}
