#pragma once
// What the kernel tests share: a vcan interface of the test's own (created,
// taken down and up, deleted and created again with `ip link`) and a raw CAN
// socket that plays the other nodes on it. These run only inside a kernel
// with CAN (tests/kernel/uml-run.sh boots one); elsewhere they skip with the
// reason.

#include <gtest/gtest.h>
#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "dh3/base/fd_util.hpp"
#include "dh3/bus/socketcan_bus.hpp"

namespace dh3::test {

/// Skips the calling test unless the kernel has CAN; use as the first line.
#define DH3_REQUIRE_KERNEL_CAN()                                                        \
  do {                                                                                  \
    if (const std::string problem = ::dh3::bus::kernel_can_support_problem();           \
        !problem.empty()) {                                                             \
      GTEST_SKIP() << problem << " (tests/kernel/uml-run.sh runs this in a kernel with CAN)"; \
    }                                                                                   \
  } while (false)

/// A vcan interface of a test's own: created and brought up with `ip link`
/// (root and the vcan module), deleted at the end; why() says what failed.
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
    if (owned_ && ::if_nametoindex(name_.c_str()) != 0) shell("ip link del dev " + name_);
  }
  OwnVcan(const OwnVcan&) = delete;
  OwnVcan& operator=(const OwnVcan&) = delete;

  [[nodiscard]] bool ready() const { return owned_ && why_.empty(); }
  [[nodiscard]] const std::string& why() const { return why_; }
  [[nodiscard]] const std::string& name() const { return name_; }
  /// Deletes the interface; true on success.
  bool remove() const { return shell("ip link del dev " + name_).empty(); }
  /// Creates it (again), up; true on success.
  bool create() const {
    return shell("ip link add dev " + name_ + " type vcan").empty() && set_up(true);
  }
  /// Deletes the interface and creates it again, up; true on success.
  bool recreate() const { return remove() && create(); }
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


/// A raw CAN socket bound to one interface, with no filter: it sees every
/// frame others send there, and what it sends reaches every other socket.
class RawCanSocket {
 public:
  explicit RawCanSocket(const std::string& interface)
      : fd_(::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW)) {
    if (!fd_) return;
    sockaddr_can address{};
    address.can_family = AF_CAN;
    address.can_ifindex = static_cast<int>(::if_nametoindex(interface.c_str()));
    if (::bind(fd_.get(), reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
      fd_.reset();
    }
  }
  [[nodiscard]] bool valid() const { return fd_.valid(); }
  [[nodiscard]] int fd() const { return fd_.get(); }

  /// Also sees error frames (and may write them: vcan delivers them as sent).
  void receive_error_frames() {
    const can_err_mask_t all = CAN_ERR_MASK;
    ::setsockopt(fd_.get(), SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &all, sizeof all);
  }

  /// Blocking send of one classic frame; false if the kernel refused it.
  bool send(std::uint32_t can_id, const std::vector<std::uint8_t>& data) {
    can_frame frame{};
    frame.can_id = can_id;
    frame.len = static_cast<std::uint8_t>(std::min<std::size_t>(data.size(), CAN_MAX_DLEN));
    std::memcpy(frame.data, data.data(), frame.len);
    return ::write(fd_.get(), &frame, sizeof frame) == static_cast<ssize_t>(sizeof frame);
  }

  /// The next frame within `timeout_ms`; an error the socket holds (ENETDOWN
  /// after the interface went down) is consumed and the wait goes on.
  std::optional<can_frame> receive(int timeout_ms = 10000) {
    for (int round = 0; round < 4; ++round) {
      pollfd p{fd_.get(), POLLIN, 0};
      if (::poll(&p, 1, timeout_ms) <= 0) return std::nullopt;
      can_frame frame{};
      const ssize_t n = ::recv(fd_.get(), &frame, sizeof frame, MSG_DONTWAIT);
      if (n == static_cast<ssize_t>(sizeof frame)) return frame;
      if (n < 0 && (errno == ENETDOWN || errno == ENODEV || errno == EAGAIN)) continue;
      return std::nullopt;
    }
    return std::nullopt;
  }

 private:
  UniqueFd fd_;
};

}  // namespace dh3::test
