#pragma once
// Byte-stream transports for the transfer box: a TCP connection or a serial
// line. A link only knows how to open a non-blocking fd and move bytes; the
// TransferBoxBus owns the fd, polls it, frames the bytes and reconnects.

#include <sys/types.h>

#include <cstdint>
#include <span>
#include <string>

#include "dh3/base/clock.hpp"
#include "dh3/base/fd_util.hpp"
#include "dh3/base/result.hpp"

namespace dh3::bus {

/// The first step of opening: a non-blocking fd that is either ready or still
/// connecting (then poll it for POLLOUT and call StreamLink::finish_open).
struct OpenStarted {
  UniqueFd fd;
  bool in_progress = false;
};

class StreamLink {
 public:
  virtual ~StreamLink() = default;
  StreamLink() = default;
  StreamLink(const StreamLink&) = delete;
  StreamLink& operator=(const StreamLink&) = delete;

  /// Starts opening without blocking on the peer. The error says why, for logs.
  virtual Result<OpenStarted, std::string> start_open() = 0;
  /// Called once an in-progress fd polled writable or failed.
  virtual Result<void, std::string> finish_open(int fd) = 0;
  /// Like write(2)/read(2) on the fd, never blocking and never raising SIGPIPE.
  virtual ssize_t write_some(int fd, std::span<const std::uint8_t> bytes) = 0;
  virtual ssize_t read_some(int fd, std::span<std::uint8_t> bytes) = 0;
  /// "tcp 127.0.0.1:9000", "serial /dev/ttyUSB0 @ 115200" for logs.
  [[nodiscard]] virtual std::string describe() const = 0;
};

struct TcpLinkOptions {
  /// A peer that stops answering (box powered off, cable pulled) is declared
  /// dead after about this long: TCP keepalive probes while idle and
  /// TCP_USER_TIMEOUT while data is unacknowledged. 0 leaves the OS defaults
  /// (which take many minutes).
  Duration dead_peer_timeout = std::chrono::seconds(10);
};

/// TCP client to HOST:PORT. Host names are resolved on every attempt, so a box
/// whose address changes is found again; each attempt tries the next address
/// of the resolution (IPv6 and IPv4 for "localhost", say).
class TcpLink final : public StreamLink {
 public:
  TcpLink(std::string host, std::uint16_t port, TcpLinkOptions options = {});
  Result<OpenStarted, std::string> start_open() override;
  Result<void, std::string> finish_open(int fd) override;
  ssize_t write_some(int fd, std::span<const std::uint8_t> bytes) override;
  ssize_t read_some(int fd, std::span<std::uint8_t> bytes) override;
  [[nodiscard]] std::string describe() const override;

 private:
  std::string host_;
  std::uint16_t port_;
  TcpLinkOptions options_;
  std::size_t next_address_ = 0;
};

/// A serial device in raw 8N1 mode at a fixed rate, no flow control. The
/// device is locked with flock() so two services cannot share it unnoticed.
class SerialLink final : public StreamLink {
 public:
  SerialLink(std::string path, std::uint32_t baud_rate);
  Result<OpenStarted, std::string> start_open() override;
  Result<void, std::string> finish_open(int fd) override;
  ssize_t write_some(int fd, std::span<const std::uint8_t> bytes) override;
  ssize_t read_some(int fd, std::span<std::uint8_t> bytes) override;
  [[nodiscard]] std::string describe() const override;

 private:
  std::string path_;
  std::uint32_t baud_rate_;
};

/// Baud rates a serial: spec may use (those termios has constants for).
[[nodiscard]] std::span<const std::uint32_t> supported_baud_rates();
[[nodiscard]] bool is_supported_baud_rate(std::uint32_t baud_rate);

}  // namespace dh3::bus
