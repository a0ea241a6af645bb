#pragma once
// A TCP proxy on a free loopback port in front of a transfer box (dh3-sim):
// every byte the service sends is recorded before it is passed on, so a test
// sees the exact frames on the wire. It also plays the faults of a real link:
//
//   cut()/restore()        the link drops (both sockets closed) and stays down:
//                          while cut, every new connection is accepted and
//                          closed at once, as a box that resets does
//   set_split(true)        every byte is written on its own, both ways, so
//                          frames arrive in pieces
//   set_garbage(true)      junk bytes (never a whole frame) are put between the
//                          box's frames on their way to the service
//
// Serves one connection at a time; everything runs on the proxy's own thread.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace dh3::test {

class RecordingProxy {
 public:
  explicit RecordingProxy(std::uint16_t backend_port) : backend_port_(backend_port) {
    listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t length = sizeof address;
    if (::bind(listen_fd_, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 ||
        ::listen(listen_fd_, 4) != 0 ||
        ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&address), &length) != 0) {
      return;
    }
    port_ = ntohs(address.sin_port);
    thread_ = std::thread([this] { run(); });
  }
  ~RecordingProxy() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
    if (listen_fd_ >= 0) ::close(listen_fd_);
  }
  RecordingProxy(const RecordingProxy&) = delete;
  RecordingProxy& operator=(const RecordingProxy&) = delete;

  [[nodiscard]] std::uint16_t port() const { return port_; }
  [[nodiscard]] std::string bus_spec() const { return "tcp:127.0.0.1:" + std::to_string(port_); }

  /// Every byte the service sent so far.
  std::vector<std::uint8_t> sent() {
    std::lock_guard lock(mutex_);
    return sent_;
  }

  /// Connections passed on to the box so far (a reconnect makes it grow).
  [[nodiscard]] int connections() const { return connections_.load(); }
  /// Junk bytes put on the way to the service so far.
  [[nodiscard]] std::size_t garbage_sent() const { return garbage_sent_.load(); }

  void cut() { cut_ = true; }
  void restore() { cut_ = false; }
  void set_split(bool on) { split_ = on; }
  void set_garbage(bool on) { garbage_ = on; }

 private:
  static constexpr std::size_t kFrameSize = 14;

  static int connect_to(std::uint16_t port) {
    const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    address.sin_port = htons(port);
    if (::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
      ::close(fd);
      return -1;
    }
    const int one = 1;
    ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    return fd;
  }

  /// Writes all of `bytes`, one byte per write() when splitting.
  bool write_all(int to, const std::uint8_t* bytes, std::size_t size) const {
    const std::size_t step = split_ ? 1 : size;
    for (std::size_t done = 0; done < size;) {
      const std::size_t chunk = std::min(step, size - done);
      const ssize_t written = ::write(to, bytes + done, chunk);
      if (written <= 0) return false;
      done += static_cast<std::size_t>(written);
    }
    return true;
  }

  /// Junk that is never a frame: stray bytes, a frame end, and headers that
  /// break off, so the service's decoder has to resynchronise.
  bool write_garbage(int to) {
    static const std::array<std::vector<std::uint8_t>, 5> kJunk{{
        {0x00},
        {0xFB, 0x13, 0x37},
        {0xFF, 0xFE, 0x00},
        {0xFF, 0xFE, 0xFD, 0x01, 0x06},
        {0x01, 0x0F, 0x01, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0xFB},
    }};
    const auto& junk = kJunk[next_junk_++ % kJunk.size()];
    garbage_sent_ += junk.size();
    return write_all(to, junk.data(), junk.size());
  }

  /// Passes what `from` has on to `to`. Toward the service the box's frames are
  /// counted, so junk goes only between whole frames.
  bool forward(int from, int to, bool from_service) {
    std::uint8_t buffer[4096];
    const ssize_t got = ::read(from, buffer, sizeof buffer);
    if (got <= 0) return false;
    const auto size = static_cast<std::size_t>(got);
    if (from_service) {
      {
        std::lock_guard lock(mutex_);
        sent_.insert(sent_.end(), buffer, buffer + got);
      }
      return write_all(to, buffer, size);
    }
    for (std::size_t at = 0; at < size;) {
      if (reply_offset_ == 0 && garbage_ && !write_garbage(to)) return false;
      const std::size_t chunk = std::min(size - at, kFrameSize - reply_offset_);
      if (!write_all(to, buffer + at, chunk)) return false;
      at += chunk;
      reply_offset_ = (reply_offset_ + chunk) % kFrameSize;
    }
    return true;
  }

  void run() {
    while (!stop_) {
      pollfd accept_poll{listen_fd_, POLLIN, 0};
      if (::poll(&accept_poll, 1, 20) <= 0) continue;
      const int client = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
      if (client < 0) continue;
      if (cut_) {
        ::close(client);
        continue;
      }
      const int one = 1;
      ::setsockopt(client, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
      const int backend = connect_to(backend_port_);
      if (backend < 0) {
        ::close(client);
        continue;
      }
      ++connections_;
      reply_offset_ = 0;
      while (!stop_ && !cut_) {
        pollfd fds[2] = {{client, POLLIN, 0}, {backend, POLLIN, 0}};
        if (::poll(fds, 2, 20) <= 0) continue;
        if ((fds[0].revents & (POLLIN | POLLHUP | POLLERR)) != 0 &&
            !forward(client, backend, true)) {
          break;
        }
        if ((fds[1].revents & (POLLIN | POLLHUP | POLLERR)) != 0 &&
            !forward(backend, client, false)) {
          break;
        }
      }
      ::close(client);
      ::close(backend);
    }
  }

  std::uint16_t backend_port_;
  int listen_fd_ = -1;
  std::uint16_t port_ = 0;
  std::atomic<bool> stop_{false};
  std::atomic<bool> cut_{false};
  std::atomic<bool> split_{false};
  std::atomic<bool> garbage_{false};
  std::atomic<int> connections_{0};
  std::atomic<std::size_t> garbage_sent_{0};
  std::size_t reply_offset_ = 0;  ///< position in the box's current frame
  std::size_t next_junk_ = 0;
  std::mutex mutex_;
  std::vector<std::uint8_t> sent_;
  std::thread thread_;
};

}  // namespace dh3::test
