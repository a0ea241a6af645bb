#pragma once
// A bare TCP client for tests that talk to a transfer box (real dh3-sim or the
// in-process server) byte for byte, without the project's codec, so the bytes
// on the wire are checked against the protocol document itself.
//
//   RawTcpClient box(port);
//   box.send_hex("FF FE FD FC 01 13 01 00 00 00 00 00 00 FB");
//   EXPECT_EQ(box.read_hex(14, 10s), "FF FE FD FC 01 13 01 00 00 00 02 01 04 FB");

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace dh3::test {

/// "FF FE 01" -> {0xFF, 0xFE, 0x01}; spaces are optional.
inline std::vector<std::uint8_t> bytes_from_hex(std::string_view hex) {
  std::vector<std::uint8_t> bytes;
  int high = -1;
  for (const char c : hex) {
    int nibble = -1;
    if (c >= '0' && c <= '9') nibble = c - '0';
    if (c >= 'A' && c <= 'F') nibble = c - 'A' + 10;
    if (c >= 'a' && c <= 'f') nibble = c - 'a' + 10;
    if (nibble < 0) continue;
    if (high < 0) {
      high = nibble;
    } else {
      bytes.push_back(static_cast<std::uint8_t>(high * 16 + nibble));
      high = -1;
    }
  }
  return bytes;
}

/// {0xFF, 0x01} -> "FF 01".
inline std::string hex_from_bytes(const std::vector<std::uint8_t>& bytes) {
  std::string text;
  for (const std::uint8_t byte : bytes) {
    char two[4];
    std::snprintf(two, sizeof two, "%02X", byte);
    if (!text.empty()) text += ' ';
    text += two;
  }
  return text;
}

class RawTcpClient {
 public:
  explicit RawTcpClient(std::uint16_t port, const char* host = "127.0.0.1") {
    fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd_ < 0) return;
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(port);
    ::inet_pton(AF_INET, host, &address.sin_addr);
    if (::connect(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
      ::close(fd_);
      fd_ = -1;
      return;
    }
    const int no_delay = 1;
    ::setsockopt(fd_, IPPROTO_TCP, TCP_NODELAY, &no_delay, sizeof no_delay);
  }
  ~RawTcpClient() {
    if (fd_ >= 0) ::close(fd_);
  }
  RawTcpClient(const RawTcpClient&) = delete;
  RawTcpClient& operator=(const RawTcpClient&) = delete;

  [[nodiscard]] bool connected() const { return fd_ >= 0; }

  bool send_bytes(const std::vector<std::uint8_t>& bytes) {
    std::size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t sent = ::send(fd_, bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL);
      if (sent < 0 && errno == EINTR) continue;
      if (sent <= 0) return false;
      done += static_cast<std::size_t>(sent);
    }
    return true;
  }
  bool send_hex(std::string_view hex) { return send_bytes(bytes_from_hex(hex)); }

  /// Exactly `count` bytes, or nullopt if the peer closes or they do not all
  /// arrive within `timeout`.
  std::optional<std::vector<std::uint8_t>> read_bytes(std::size_t count,
                                                      std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    std::vector<std::uint8_t> bytes;
    while (bytes.size() < count) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0) return std::nullopt;
      pollfd poll_fd{fd_, POLLIN, 0};
      const int ready = ::poll(&poll_fd, 1, static_cast<int>(left.count()));
      if (ready < 0 && errno == EINTR) continue;
      if (ready <= 0) return std::nullopt;
      std::uint8_t chunk[64];
      const std::size_t want = std::min(sizeof chunk, count - bytes.size());
      const ssize_t got = ::recv(fd_, chunk, want, 0);
      if (got < 0 && errno == EINTR) continue;
      if (got <= 0) return std::nullopt;
      bytes.insert(bytes.end(), chunk, chunk + got);
    }
    return bytes;
  }

  /// The next `count` bytes as "FF FE ...", or "<nothing>" if they do not come.
  std::string read_hex(std::size_t count, std::chrono::milliseconds timeout) {
    const auto bytes = read_bytes(count, timeout);
    return bytes ? hex_from_bytes(*bytes) : std::string("<nothing>");
  }

  /// True once the peer has closed the connection (within `timeout`); bytes
  /// still arriving before the close are read and dropped.
  bool wait_closed(std::chrono::milliseconds timeout) {
    return read_until_closed(timeout).has_value();
  }

  /// Everything the peer sends until it closes the connection, or nullopt if
  /// it does not close within `timeout`.
  std::optional<std::string> read_until_closed(std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    std::string received;
    for (;;) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0) return std::nullopt;
      pollfd poll_fd{fd_, POLLIN, 0};
      const int ready = ::poll(&poll_fd, 1, static_cast<int>(left.count()));
      if (ready < 0 && errno == EINTR) continue;
      if (ready <= 0) return std::nullopt;
      char chunk[4096];
      const ssize_t got = ::recv(fd_, chunk, sizeof chunk, 0);
      if (got > 0) received.append(chunk, static_cast<std::size_t>(got));
      if (got == 0 || (got < 0 && errno != EINTR && errno != EAGAIN)) return received;
    }
  }

 private:
  int fd_ = -1;
};

}  // namespace dh3::test
