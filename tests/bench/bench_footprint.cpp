// Footprint (benchmark 5): dh3-service (a child process) with 1, 32
// and 255 simulated hands at idle, i.e. no commands, only its status polling
// (the default timings: every 500 ms per idle hand) and no client connected:
// resident memory (VmRSS, VmHWM from /proc/PID/status) and CPU (utime + stime
// from /proc/PID/stat) over a window after a warm-up. And the client library's
// memory: the RSS of a process that created a dh3::Client and received every
// hand's status, minus that process's RSS just before it created the client
// (the libraries are loaded by then: that baseline holds their relocated pages,
// the difference is what the client allocates and touches).
//
//   bench_footprint [--warmup S] [--seconds S] [--json FILE]
//   bench_footprint --role client --domain D --service NAME --hands N   (internal)

#include <spdlog/spdlog.h>

#include <cstdio>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "bench_util.hpp"
#include "dh3/client.hpp"

namespace {

using namespace std::chrono_literals;
using namespace dh3;
using bench::BenchClock;

/// Prints "client BASELINE_KIB WITH_CLIENT_KIB HANDS_SEEN" once the client has
/// the status of `hands` hands of `service` (or after 60 s).
int run_client(int domain, const std::string& service, int hands) {
  const long baseline = bench::status_kib(::getpid(), "VmRSS:").value_or(0);
  ClientOptions options;
  options.domain = domain;
  options.participant_name = "dh3-bench-footprint";
  Client client(options);
  std::size_t seen = 0;
  const auto deadline = BenchClock::now() + 60s;
  while (BenchClock::now() < deadline) {
    seen = 0;
    for (const auto& status : client.hands()) {
      seen += status.address.service == service && status.online ? 1 : 0;
    }
    if (seen >= static_cast<std::size_t>(hands)) break;
    std::this_thread::sleep_for(20ms);  // polling the hands seen
  }
  const long with_client = bench::status_kib(::getpid(), "VmRSS:").value_or(0);
  std::printf("client %ld %ld %zu\n", baseline, with_client, seen);
  return 0;
}

struct Row {
  int hands = 0;
  double rss_mib = 0;
  double hwm_mib = 0;
  double cpu_percent = 0;
  double client_mib = 0;
  std::size_t client_hands_seen = 0;
};

Row measure(int hands, double warmup, double seconds) {
  const int domain = bench::bench_domain();
  const std::string service = "footprint";
  bench::ServiceChild child(
      "buses:\n  - name: bus0\n    spec: sim:" + bench::hand_ids(hands) + "\n", domain, service,
      false);
  Row row;
  row.hands = hands;
  {
    test::Process client(bench::self_path(),
                         {"--role", "client", "--domain", std::to_string(domain), "--service",
                          service, "--hands", std::to_string(hands)});
    long baseline = 0;
    long with_client = 0;
    if (const auto line = client.wait_for_line("client", 90s)) {
      std::sscanf(line->c_str(), "client %ld %ld %zu", &baseline, &with_client,
                  &row.client_hands_seen);
    }
    client.wait_exit(20s);
    row.client_mib = static_cast<double>(with_client - baseline) / 1024;
  }
  std::this_thread::sleep_for(std::chrono::duration<double>(warmup));  // warm-up
  const double cpu_before = bench::cpu_seconds_of(child.pid());
  const auto started = BenchClock::now();
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));  // the window
  const double cpu = bench::cpu_seconds_of(child.pid()) - cpu_before;
  const double window = std::chrono::duration<double>(BenchClock::now() - started).count();
  row.cpu_percent = 100 * cpu / window;
  row.rss_mib = static_cast<double>(bench::status_kib(child.pid(), "VmRSS:").value_or(0)) / 1024;
  row.hwm_mib = static_cast<double>(bench::status_kib(child.pid(), "VmHWM:").value_or(0)) / 1024;
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Footprint: dh3-service at idle with 1, 32 and 255 hands; client library memory"};
  bench::CommonOptions common;
  bench::add_common_options(app, common);
  double warmup = 3;
  double seconds = 5;
  int hands = 0;
  app.add_option("--warmup", warmup, "Seconds after start before measuring")->capture_default_str();
  app.add_option("--seconds", seconds, "Seconds measured per row")->capture_default_str();
  app.add_option("--hands", hands, "(client role) hands to wait for");
  CLI11_PARSE(app, argc, argv);
  auto& [json_path, role, domain, service] = common;
  spdlog::set_level(spdlog::level::warn);
  if (role == "client") return run_client(domain, service, hands);

  std::vector<Row> rows;
  for (const int count : {1, 32, 255}) rows.push_back(measure(count, warmup, seconds));

  std::printf("Footprint: dh3-service idle (status polling only), %.0f s warm-up, %.0f s window\n",
              warmup, seconds);
  std::printf("%6s %10s %10s %10s %14s %12s\n", "hands", "RSS MiB", "HWM MiB", "cpu %",
              "client MiB", "client saw");
  for (const Row& r : rows) {
    std::printf("%6d %10.1f %10.1f %9.2f%% %14.1f %12zu\n", r.hands, r.rss_mib, r.hwm_mib,
                r.cpu_percent, r.client_mib, r.client_hands_seen);
  }
  if (!json_path.empty()) {
    std::FILE* f = std::fopen(json_path.c_str(), "w");
    if (f == nullptr) {
      std::perror(json_path.c_str());
      return 1;
    }
    std::fprintf(f, "{\"benchmark\":\"footprint\",\"warmup_s\":%g,\"seconds\":%g,\"rows\":[",
                 warmup, seconds);
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const Row& r = rows[i];
      std::fprintf(f,
                   "%s{\"hands\":%d,\"service_rss_mib\":%.2f,\"service_hwm_mib\":%.2f,"
                   "\"service_cpu_percent\":%.3f,\"client_mib\":%.2f,\"client_hands_seen\":%zu}",
                   i == 0 ? "" : ",", r.hands, r.rss_mib, r.hwm_mib, r.cpu_percent, r.client_mib,
                   r.client_hands_seen);
    }
    std::fprintf(f, "]}\n");
    std::fclose(f);
  }
  return 0;
}
