#pragma once
// What the tests of dh3-sim's two transports (TransferBoxServer, CanServer)
// share: fast hands, pipes for the control channel, and a server on a thread.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <memory>
#include <string>
#include <thread>

#include "dh3/sim/sim_hand.hpp"

namespace dh3::sim::test {

/// A hand that initializes in 20 ms.
inline SimHandOptions fast_hand(std::uint8_t id) {
  SimHandOptions options;
  options.id = id;
  options.init_time = std::chrono::milliseconds(20);
  return options;
}

/// A pipe whose ends close with it.
struct Pipe {
  Pipe() { EXPECT_EQ(::pipe2(fds, O_CLOEXEC), 0); }
  ~Pipe() {
    close_read();
    close_write();
  }
  Pipe(const Pipe&) = delete;
  Pipe& operator=(const Pipe&) = delete;
  void close_read() {
    if (fds[0] >= 0) ::close(fds[0]);
    fds[0] = -1;
  }
  void close_write() {
    if (fds[1] >= 0) ::close(fds[1]);
    fds[1] = -1;
  }
  [[nodiscard]] int read_end() const { return fds[0]; }
  [[nodiscard]] int write_end() const { return fds[1]; }
  int fds[2] = {-1, -1};
};

inline void write_text(int fd, const std::string& text) {
  ASSERT_EQ(::write(fd, text.data(), text.size()), static_cast<ssize_t>(text.size()));
}

/// Reads one line from `fd` (blocking; the servers answer every command).
inline std::string read_line(int fd) {
  std::string line;
  char c = 0;
  while (::read(fd, &c, 1) == 1 && c != '\n') line += c;
  return line;
}

/// A server (anything with run() and request_stop()) on its own thread until
/// stopped or destroyed.
template <typename Server>
class ServerThread {
 public:
  explicit ServerThread(std::unique_ptr<Server> server) : server_(std::move(server)) {
    if (server_) thread_ = std::thread([this] { server_->run(); });
  }
  ~ServerThread() { stop(); }
  ServerThread(const ServerThread&) = delete;
  ServerThread& operator=(const ServerThread&) = delete;

  [[nodiscard]] bool started() const { return server_ != nullptr; }
  Server& server() { return *server_; }
  /// Waits for run() to return by itself (a `quit` command).
  void join() {
    if (thread_.joinable()) thread_.join();
  }
  void stop() {
    if (server_) server_->request_stop();
    join();
  }

 private:
  std::unique_ptr<Server> server_;
  std::thread thread_;
};

}  // namespace dh3::sim::test
