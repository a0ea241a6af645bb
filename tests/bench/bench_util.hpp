#pragma once
// What the benchmarks that run dh3-service and the client library share:
// percentiles, a process's memory and CPU time from /proc, the benchmark's own
// path (to start itself in another role), a DDS domain of its own, the
// dh3-service child process with a sim bus config, and the options they all take.

#include <sys/types.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "support/process.hpp"

namespace dh3::bench {

/// What every such benchmark takes: where to write its JSON, and what it
/// passes to itself when it starts itself in another role (a child process).
struct CommonOptions {
  std::string json_path;
  std::string role;  ///< empty: the benchmark itself; otherwise the child's role
  int domain = 0;
  std::string service;
};

inline void add_common_options(CLI::App& app, CommonOptions& options) {
  app.add_option("--json", options.json_path, "Also write the results as JSON to this file");
  auto* child = app.add_option_group("child", "Set by the benchmark when it starts itself");
  child->add_option("--role", options.role, "Run as this child role");
  child->add_option("--domain", options.domain, "DDS domain of the run");
  child->add_option("--service", options.service, "Name of the dh3-service under test");
}

using BenchClock = std::chrono::steady_clock;

inline double micros_between(BenchClock::time_point from, BenchClock::time_point to) {
  return std::chrono::duration<double, std::micro>(to - from).count();
}

struct Percentiles {
  std::size_t count = 0;
  double p50 = 0;
  double p90 = 0;
  double p99 = 0;
  double max = 0;
};

/// Nearest-rank percentiles of `samples` (sorted in place).
inline Percentiles percentiles(std::vector<double>& samples) {
  Percentiles p;
  p.count = samples.size();
  if (samples.empty()) return p;
  std::sort(samples.begin(), samples.end());
  const auto rank = [&](double q) {
    const auto index = static_cast<std::size_t>(std::ceil(q * static_cast<double>(p.count)));
    return samples[std::clamp<std::size_t>(index, 1, p.count) - 1];
  };
  p.p50 = rank(0.50);
  p.p90 = rank(0.90);
  p.p99 = rank(0.99);
  p.max = samples.back();
  return p;
}

inline std::string to_json(const Percentiles& p) {
  char text[160];
  std::snprintf(text, sizeof text,
                "{\"count\":%zu,\"p50_us\":%.1f,\"p90_us\":%.1f,"
                "\"p99_us\":%.1f,\"max_us\":%.1f}",
                p.count, p.p50, p.p90, p.p99, p.max);
  return text;
}

/// A "VmRSS:"-style field of /proc/PID/status in KiB; nullopt if unreadable.
inline std::optional<long> status_kib(pid_t pid, const std::string& field) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(field, 0) == 0) return std::stol(line.substr(field.size()));
  }
  return std::nullopt;
}

/// User plus system CPU time of a process so far, in seconds (/proc/PID/stat).
inline double cpu_seconds_of(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // Fields after the command name (which may hold spaces) start after the last ')'.
  const auto close = text.rfind(')');
  if (close == std::string::npos) return 0;
  std::istringstream fields(text.substr(close + 2));
  std::string field;
  unsigned long long utime = 0;
  unsigned long long stime = 0;
  // state is field 3; utime and stime are fields 14 and 15.
  for (int index = 3; index <= 15 && fields >> field; ++index) {
    if (index == 14) utime = std::stoull(field);
    if (index == 15) stime = std::stoull(field);
  }
  return static_cast<double>(utime + stime) / static_cast<double>(::sysconf(_SC_CLK_TCK));
}

/// Context switches (voluntary and not) of every live thread of a process so
/// far: how often its threads went to sleep or were preempted.
inline std::uint64_t context_switches_of(pid_t pid) {
  std::uint64_t total = 0;
  const std::string tasks = "/proc/" + std::to_string(pid) + "/task";
  for (const auto& task : std::filesystem::directory_iterator(tasks)) {
    std::ifstream in(task.path() / "status");
    std::string line;
    while (std::getline(in, line)) {
      if (line.find("ctxt_switches:") != std::string::npos) {
        total += std::stoull(line.substr(line.find(':') + 1));
      }
    }
  }
  return total;
}

/// This program's path, to start it again in another role.
inline std::string self_path() {
  char path[4096];
  const ssize_t length = ::readlink("/proc/self/exe", path, sizeof path - 1);
  return length > 0 ? std::string(path, static_cast<std::size_t>(length)) : std::string();
}

/// A DDS domain apart from the tests' (10-209, tests/integration): 210-229.
inline int bench_domain() {
  return 210 + static_cast<int>(::getpid() % 20);
}

/// A file that exists as long as this object does.
class TempConfig {
 public:
  explicit TempConfig(const std::string& yaml) {
    static std::atomic<int> counter{0};
    path_ =
        "/tmp/dh3-bench-" + std::to_string(::getpid()) + "-" + std::to_string(++counter) + ".yaml";
    std::ofstream(path_) << yaml;
  }
  ~TempConfig() { std::remove(path_.c_str()); }
  TempConfig(const TempConfig&) = delete;
  TempConfig& operator=(const TempConfig&) = delete;
  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  std::string path_;
};

/// "1,2,...,count": the CAN IDs of `count` simulated hands.
inline std::string hand_ids(int count) {
  std::string ids;
  for (int id = 1; id <= count; ++id) ids += (id == 1 ? "" : ",") + std::to_string(id);
  return ids;
}

/// dh3-service as a child process (logs at warn) with `config_yaml`, on
/// `domain` under `name`; stopped with SIGTERM when this object goes away.
class ServiceChild {
 public:
  /// `binary`: another dh3-service build to run (e.g. an older one, to compare).
  ServiceChild(const std::string& config_yaml, int domain, const std::string& name, bool udp_only,
               const std::string& binary = DH3_SERVICE_PATH)
      : config_(config_yaml),
        process_(binary, args(domain, name, udp_only), test::Process::Stdin::dev_null) {}
  ~ServiceChild() { stop(); }
  ServiceChild(const ServiceChild&) = delete;
  ServiceChild& operator=(const ServiceChild&) = delete;

  [[nodiscard]] pid_t pid() const { return process_.pid(); }
  /// Sends `signal_number` (a kill, a freeze); stop() still reaps it.
  bool signal(int signal_number) { return process_.send_signal(signal_number); }
  void stop() {
    if (stopped_) return;
    stopped_ = true;
    process_.send_signal(SIGTERM);
    process_.wait_exit(std::chrono::seconds(20));
  }

 private:
  std::vector<std::string> args(int domain, const std::string& name, bool udp_only) const {
    std::vector<std::string> list{"--config", config_.path(), "--domain",    std::to_string(domain),
                                  "--name",   name,           "--log-level", "warn"};
    // The "shm" rows ask for shared memory: not the default.
    list.emplace_back(udp_only ? "--udp-only" : "--shared-memory");
    return list;
  }
  TempConfig config_;
  test::Process process_;
  bool stopped_ = false;
};

}  // namespace dh3::bench
