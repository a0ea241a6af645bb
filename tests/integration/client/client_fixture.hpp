#pragma once
// What the client integration tests share: dh3-service on a simulated bus of
// three hands (hand 1 has an object between its fingers at 40), a dh3::Client
// on the test's own domain, and dh3ctl / pick_loop as child processes.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "dh3/client.hpp"
#include "integration/service/service_fixture.hpp"

namespace dh3::test {

inline constexpr std::chrono::seconds kClientDeadline{20};

/// A sim bus "bus0" with hands 1-3, fast so tests are quick; hand 1 holds an
/// object at position 40. `init_time_ms`: how long initialization takes.
inline std::string sim_config(int init_time_ms = 50) {
  return "buses:\n"
         "  - name: bus0\n"
         "    spec: sim\n"
         "    command_interval_ms: 2\n"
         "    poll_interval_moving_ms: 20\n"
         "    poll_interval_idle_ms: 50\n"
         "    init_timeout_ms: 120000\n"
         "    sim: {reply_delay_ms: 1, position_speed: 400, rotation_speed: 400, init_time_ms: " +
         std::to_string(init_time_ms) +
         "}\n"
         "    hands:\n"
         "      - {id: 1, object: 40}\n"
         "      - {id: 2}\n"
         "      - {id: 3}\n";
}

inline ClientOptions client_options() {
  ClientOptions options;
  options.domain = test_domain();
  options.default_timeout = kClientDeadline;
  return options;
}

/// "svc1234/bus0/2"
inline std::string hand_spec(std::uint16_t id) {
  return test_service_name() + "/bus0/" + std::to_string(id);
}

inline HandAddress hand_address(std::uint16_t id) {
  return {test_service_name(), "bus0", id};
}

/// dh3-service with `config` (a YAML text), as a child process.
class RunningService {
 public:
  explicit RunningService(const std::string& config)
      : config_(std::make_unique<TempFile>(config)),
        process_(std::make_unique<ServiceProcess>(
            std::vector<std::string>{"--config", config_->path(), "--log-level", "warn"})) {}
  [[nodiscard]] bool started() const { return process_->started(); }
  ServiceProcess& process() { return *process_; }

 private:
  std::unique_ptr<TempFile> config_;
  std::unique_ptr<ServiceProcess> process_;
};

/// A finished child process: its exit code and stdout lines.
struct Finished {
  std::optional<int> exit_code;  ///< nullopt: did not exit normally in time
  std::vector<std::string> lines;
  [[nodiscard]] std::string text() const {
    std::string all;
    for (const auto& line : lines) all += line + "\n";
    return all;
  }
};

/// Runs a program to its end, collecting its stdout.
inline Finished run_program(const std::string& path, const std::vector<std::string>& args,
                            std::chrono::milliseconds timeout = std::chrono::seconds(60)) {
  Process process(path, args, Process::Stdin::dev_null);
  Finished finished;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (auto line = process.read_line(std::chrono::duration_cast<std::chrono::milliseconds>(
             deadline - std::chrono::steady_clock::now()))) {
    finished.lines.push_back(*line);
  }
  const auto status =
      process.wait_exit(std::chrono::duration_cast<std::chrono::milliseconds>(std::max(
          deadline - std::chrono::steady_clock::now(), std::chrono::steady_clock::duration{})));
  if (status && WIFEXITED(*status)) finished.exit_code = WEXITSTATUS(*status);
  return finished;
}

/// dh3ctl on this test's domain: `dh3ctl --domain D --timeout 20 ARGS...`.
inline std::vector<std::string> ctl_args(std::vector<std::string> args) {
  args.insert(args.begin(), {"--domain", std::to_string(test_domain()), "--timeout", "20"});
  return args;
}

inline Finished dh3ctl(const std::vector<std::string>& args) {
  return run_program(DH3CTL_PATH, ctl_args(args));
}

}  // namespace dh3::test
