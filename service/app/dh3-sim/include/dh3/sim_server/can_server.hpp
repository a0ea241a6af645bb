#pragma once
// Simulated DH-3 hands as nodes on a CAN interface: they receive the frames
// with their CAN ID (and ID 0) and answer with the same 8-byte payloads they
// send behind the transfer box, unsolicited frames (initialization finished)
// included. One of dh3-sim's transports (the other is TransferBoxServer); the
// hands, the control channel and the interval check are SimHost's.
//
// Like SocketCanBus, the server runs on a file descriptor carrying `struct
// can_frame` datagrams that a CanSocketOpener provides: dh3-sim's opener binds
// a CAN_RAW socket to an interface such as vcan0 (open_can_raw_socket()); tests
// hand over one end of an AF_UNIX SOCK_SEQPACKET socketpair and play the bus on
// the other end.
// Received frames are checked in user space whatever the fd: only standard data
// frames (not extended, RTR or error frames) with IDs 0-255 and exactly 8 data
// bytes that decode as a DH-3 payload reach the hands; the rest are counted as
// foreign and ignored.
//
// Interval check: a frame's time is the kernel's receive timestamp
// (SO_TIMESTAMPNS, taken when the frame reached the socket) when the fd
// delivers one, so a sim that reads late does not see two frames closer than
// they were on the bus; otherwise the clock at the read.
//
// The bus going away does not stop the hands. An interface that goes down
// (ENETDOWN) is logged and waited for: the socket stays bound and works again
// when it is up. An fd that fails otherwise (interface deleted: ENODEV; the
// peer of a socketpair closed) is closed and reopened through the opener every
// `reopen_interval` until it works; replies due meanwhile are lost, as a real
// hand's would be.
//
// Threading: run() serves everything on the calling thread with poll(); only
// request_stop() may be called from elsewhere (also from a signal handler).

#include <sys/socket.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dh3/bus/can_socket.hpp"
#include "dh3/base/clock.hpp"
#include "dh3/base/fd_util.hpp"
#include "dh3/base/result.hpp"
#include "dh3/sim_server/sim_host.hpp"

namespace dh3::sim {

/// The hands, control channel and interval check (SimHostOptions) and the interface.
struct CanServerOptions : SimHostOptions {
  /// The interface's name, for log lines ("vcan0").
  std::string interface_name = "can";
  /// How often a lost interface is tried again.
  Duration reopen_interval = std::chrono::milliseconds(500);
};

class CanServer final : private SimTransport {
 public:
  /// Opens the interface through `opener` once now; fails with the opener's
  /// reason (or the OS's, for the wake-up pipe). The hands start now.
  [[nodiscard]] static Result<std::unique_ptr<CanServer>, std::string> open(
      CanServerOptions options, bus::CanSocketOpener opener, const Clock& clock);
  CanServer(const CanServer&) = delete;
  CanServer& operator=(const CanServer&) = delete;

  /// Serves the interface, the hands and the control channel until
  /// request_stop() or a `quit` command.
  void run();
  /// Makes run() return soon. Any thread; async-signal-safe.
  void request_stop() { host_.request_stop(); }
  /// Executes one control command and returns its answer line (no newline).
  /// Only on run()'s thread, or while run() is not running.
  std::string execute(std::string_view command) { return host_.execute(command, *this); }

  [[nodiscard]] std::size_t hand_count() const { return host_.hand_count(); }
  /// Interval violations over all hands so far (run()'s thread, or after it).
  [[nodiscard]] std::uint64_t interval_violations() const { return host_.interval_violations(); }

  /// Diagnostics (run()'s thread, or after it).
  struct Counters {
    std::uint64_t frames_received = 0;  ///< DH-3 payloads, to any ID
    std::uint64_t foreign_frames = 0;   ///< ignored: not a standard 8-byte DH-3 frame to 0-255
    std::uint64_t frames_sent = 0;
    std::uint64_t frames_lost = 0;  ///< not sent: interface down or gone, queue full
    std::uint64_t reopens = 0;      ///< times the fd was opened again after a loss
  };
  [[nodiscard]] Counters counters() const { return counters_; }

 private:
  CanServer(CanServerOptions options, bus::CanSocketOpener opener, const Clock& clock);
  [[nodiscard]] Result<void, std::string> open_fd();

  // SimTransport
  void add_poll_fds(std::vector<pollfd>& fds) override;
  void on_poll(std::span<const pollfd> fds) override;
  void send(std::uint64_t destination, const protocol::Message& message) override;
  [[nodiscard]] std::optional<TimePoint> next_timer() const override;
  void on_timer(TimePoint now) override;

  void read_frames();
  void handle_frame(const void* data, std::size_t size, std::optional<Duration> received);
  /// An error from recvmsg()/send(): waits out ENETDOWN, closes the fd otherwise.
  void handle_error(int error, std::string_view during);
  void lose_fd(std::string_view reason);
  void note_working();

  CanServerOptions options_;
  bus::CanSocketOpener opener_;
  SimHost host_;
  UniqueFd fd_;
  TimePoint next_reopen_{};
  bool down_reported_ = false;
  Counters counters_;
};

}  // namespace dh3::sim
