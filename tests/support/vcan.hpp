#pragma once
// A vcan interface of a test's own, for tests that need the kernel's CAN
// (tests named *Kernel*, run inside a real kernel by tests/kernel/). Creating
// one needs root (or CAP_NET_ADMIN) and the vcan module; when that fails the
// test skips with why().
//
//   dh3::test::OwnVcan vcan("dh3simvcan");
//   if (!vcan.ready()) GTEST_SKIP() << vcan.why();
//   ... vcan.name() ...

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>

namespace dh3::test {

class OwnVcan {
 public:
  /// Creates and brings up `prefix` + this process's id (at most 15 characters).
  explicit OwnVcan(const std::string& prefix)
      : name_((prefix + std::to_string(::getpid() % 100000)).substr(0, 15)) {
    const std::string created = shell("ip link add dev " + name_ + " type vcan");
    if (!created.empty()) {
      why_ = "cannot create a vcan interface (`ip link add dev " + name_ +
             " type vcan` needs root and the vcan module): " + created;
      return;
    }
    owned_ = true;
    if (const std::string up = shell("ip link set up dev " + name_); !up.empty()) {
      why_ = "cannot bring " + name_ + " up: " + up;
    }
  }
  ~OwnVcan() {
    if (owned_) shell("ip link del dev " + name_);
  }
  OwnVcan(const OwnVcan&) = delete;
  OwnVcan& operator=(const OwnVcan&) = delete;

  [[nodiscard]] bool ready() const { return owned_ && why_.empty(); }
  [[nodiscard]] const std::string& why() const { return why_; }
  [[nodiscard]] const std::string& name() const { return name_; }
  /// Deletes the interface and creates it again, up; true on success.
  bool recreate() const {
    return shell("ip link del dev " + name_).empty() &&
           shell("ip link add dev " + name_ + " type vcan").empty() && set_up(true);
  }
  /// `ip link set up|down`; true on success.
  bool set_up(bool up) const {
    return shell("ip link set " + std::string(up ? "up" : "down") + " dev " + name_).empty();
  }

 private:
  /// Runs `command`; empty on success, else its output (or its exit status).
  static std::string shell(const std::string& command) {
    FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
    if (pipe == nullptr) return "popen failed";
    std::string output;
    char buffer[256];
    while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) output += buffer;
    const int status = ::pclose(pipe);
    if (status == 0) return {};
    while (!output.empty() && (output.back() == '\n' || output.back() == ' ')) output.pop_back();
    return output.empty() ? "exit status " + std::to_string(status) : output;
  }

  std::string name_;
  std::string why_;
  bool owned_ = false;
};

}  // namespace dh3::test
