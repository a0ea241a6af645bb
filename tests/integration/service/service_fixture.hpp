#pragma once
// What the dh3-service integration tests share: a DDS domain and service name
// of their own (so concurrent ctest runs do not meet), the service and dh3-sim
// as child processes, config files, and a recording TCP proxy that captures
// the exact bytes the service sends to a transfer box (support/recording_proxy.hpp).

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "support/dds_test_client.hpp"
#include "support/process.hpp"
#include "support/recording_proxy.hpp"
#include "support/test_domain.hpp"

namespace dh3::test {

/// A service name no other test process uses.
inline std::string test_service_name() {
  return "svc" + std::to_string(::getpid());
}

/// A file that exists as long as this object does.
class TempFile {
 public:
  explicit TempFile(const std::string& content, const std::string& suffix = ".yaml") {
    static std::atomic<int> counter{0};
    path_ =
        "/tmp/dh3-test-" + std::to_string(::getpid()) + "-" + std::to_string(++counter) + suffix;
    std::ofstream(path_) << content;
  }
  ~TempFile() { std::remove(path_.c_str()); }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  std::string path_;
};

/// dh3-service as a child process on this test's domain, under this test's
/// service name. Its logs (stderr) show in the test output.
class ServiceProcess {
 public:
  explicit ServiceProcess(std::vector<std::string> args,
                          const std::string& name = test_service_name())
      : name_(name),
        process_(DH3_SERVICE_PATH, with_defaults(std::move(args), name), Process::Stdin::dev_null) {
  }

  [[nodiscard]] bool started() const { return process_.started(); }
  [[nodiscard]] const std::string& name() const { return name_; }
  Process& process() { return process_; }

  /// Sends `signal_number` and waits for the exit; the exit code, or nullopt
  /// if it did not exit normally in time.
  std::optional<int> stop(int signal_number = SIGTERM,
                          std::chrono::milliseconds timeout = std::chrono::seconds(20)) {
    process_.send_signal(signal_number);
    const auto status = process_.wait_exit(timeout);
    if (!status || !WIFEXITED(*status)) return std::nullopt;
    return WEXITSTATUS(*status);
  }

 private:
  static std::vector<std::string> with_defaults(std::vector<std::string> args,
                                                const std::string& name) {
    args.insert(args.begin(), {"--domain", std::to_string(test_domain()), "--name", name});
    return args;
  }
  std::string name_;
  Process process_;
};

/// dh3-service with --metrics 127.0.0.1:0 and its log joined to stdout, so
/// the test can read the address the metrics endpoint was bound to.
class MetricsService {
 public:
  explicit MetricsService(const std::string& config_path)
      : process_("/bin/sh",
                 {"-c", "exec " + std::string(DH3_SERVICE_PATH) + " --domain " +
                            std::to_string(test_domain()) + " --name " + name_ + " --config " +
                            config_path + " --metrics 127.0.0.1:0 2>&1"},
                 Process::Stdin::dev_null) {
    const std::string marker = "metrics at http://127.0.0.1:";
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (std::chrono::steady_clock::now() < deadline) {
      auto line = process_.read_line(std::chrono::seconds(1));
      if (!line) continue;
      std::fprintf(stderr, "%s\n", line->c_str());
      const auto at = line->find(marker);
      if (at == std::string::npos) continue;
      port_ = static_cast<std::uint16_t>(std::stoi(line->substr(at + marker.size())));
      return;
    }
  }

  [[nodiscard]] std::uint16_t port() const { return port_; }
  [[nodiscard]] const std::string& name() const { return name_; }

  std::optional<int> stop() {
    process_.send_signal(SIGTERM);
    // Read the log to its end, so a full pipe never holds the service up.
    while (auto line = process_.read_line(std::chrono::seconds(20))) std::fprintf(stderr, "%s\n", line->c_str());
    const auto status = process_.wait_exit(std::chrono::seconds(20));
    if (!status || !WIFEXITED(*status)) return std::nullopt;
    return WEXITSTATUS(*status);
  }

 private:
  std::string name_ = test_service_name();
  Process process_;
  std::uint16_t port_ = 0;
};

/// Runs dh3-service with stderr joined to stdout until it exits; its exit
/// code (-1 if it did not exit normally) and output.
inline std::pair<int, std::string> run_to_exit(const std::string& args) {
  Process shell("/bin/sh", {"-c", std::string(DH3_SERVICE_PATH) + " " + args + " 2>&1"},
                Process::Stdin::dev_null);
  std::string output;
  while (auto line = shell.read_line(std::chrono::seconds(20))) output += *line + "\n";
  const auto status = shell.wait_exit(std::chrono::seconds(20));
  return {status && WIFEXITED(*status) ? WEXITSTATUS(*status) : -1, output};
}

/// dh3-sim as a child process with the control channel on its stdin: a
/// transfer box on a free loopback port, or with `can_interface` the hands as
/// nodes on that CAN interface.
class SimProcess {
 public:
  explicit SimProcess(std::vector<std::string> args, const std::string& can_interface = {})
      : process_(DH3_SIM_PATH, transport_args(std::move(args), can_interface)) {
    if (!can_interface.empty()) {
      serving_ = process_.wait_for_line("serving ", std::chrono::seconds(10)).has_value();
      return;
    }
    if (auto line = process_.wait_for_line("listening ", std::chrono::seconds(10))) {
      const auto colon = line->rfind(':');
      port_ = static_cast<std::uint16_t>(std::stoi(line->substr(colon + 1)));
    }
  }
  [[nodiscard]] std::uint16_t port() const { return port_; }
  [[nodiscard]] std::string bus_spec() const { return "tcp:127.0.0.1:" + std::to_string(port_); }
  /// On CAN: it said it serves its hands.
  [[nodiscard]] bool serving() const { return serving_; }
  Process& process() { return process_; }

  /// Runs a control command; its answer line ("ok ..." or "error ...").
  std::string control(const std::string& command) {
    if (!process_.write_line(command)) return "error: dh3-sim's stdin is closed";
    for (;;) {
      auto line = process_.read_line(std::chrono::seconds(10));
      if (!line) return "error: no answer from dh3-sim";
      if (line->starts_with("ok") || line->starts_with("error")) return *line;
    }
  }

 private:
  static std::vector<std::string> transport_args(std::vector<std::string> args,
                                                 const std::string& can_interface) {
    if (can_interface.empty()) {
      args.insert(args.begin(), {"--listen", "127.0.0.1:0"});
    } else {
      args.insert(args.begin(), {"--can", can_interface});
    }
    return args;
  }
  Process process_;
  std::uint16_t port_ = 0;
  bool serving_ = false;
};

/// "FF FE FD FC 01 06 02 01 00 3C 00 00 00 FB" for each 14-byte frame in `bytes`.
inline std::vector<std::string> frames_as_hex(const std::vector<std::uint8_t>& bytes) {
  std::vector<std::string> frames;
  for (std::size_t at = 0; at + 14 <= bytes.size(); at += 14) {
    std::string text;
    for (std::size_t i = 0; i < 14; ++i) {
      char byte[4];
      std::snprintf(byte, sizeof byte, i == 0 ? "%02X" : " %02X", bytes[at + i]);
      text += byte;
    }
    frames.push_back(std::move(text));
  }
  return frames;
}

/// The frames written (read/write byte 01) among `frames` (frames_as_hex's form).
inline std::vector<std::string> written_frames(const std::vector<std::string>& frames) {
  std::vector<std::string> out;
  for (const auto& frame : frames) {
    if (frame.substr(21, 2) == "01") out.push_back(frame);
  }
  return out;
}

/// A client on this test's domain that waited for `service` to answer.
inline std::unique_ptr<DdsTestClient> connected_client(const std::string& service,
                                                       const std::string& name = "dh3-test") {
  auto client = std::make_unique<DdsTestClient>(test_domain(), name);
  if (!client->ok() || !client->wait_for_service(service)) return nullptr;
  return client;
}

}  // namespace dh3::test
