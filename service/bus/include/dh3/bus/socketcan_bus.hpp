#pragma once
// Linux SocketCAN: a CAN_RAW socket bound to an interface such as can0, with a
// kernel receive filter for what DH-3 hands send (standard 11-bit data frames
// with ids 0-0xFF) plus the controller's error frames.
//
// Everything after socket()/bind() runs on one fd-based path: the bus gets its
// fd from an opener function, which for a real interface opens and binds the
// CAN socket and in tests may hand over one end of an AF_UNIX socketpair
// carrying `struct can_frame` datagrams. That path re-checks in user space what
// the kernel filter promises (standard, non-RTR, id <= 0xFF, length <= 8), so
// it is the same whichever fd it runs on.
//
// When the interface goes down (ENETDOWN), disappears, or the fd fails or
// reaches EOF, the bus reports link_down and reopens through the opener with
// backoff during later receive() calls.
//
// The controller's error frames are counted by kind (diagnostics()) and
// logged, at most once per kind every few seconds except for bus-off and its
// end. Bus-off takes the link down with the socket kept open, until the
// controller reports that it restarted (or frames arrive again, or the
// interface is taken down and up). Frames the kernel drops because the
// receive queue was full are counted from the socket's SO_RXQ_OVFL figure,
// which the kernel hands over with the next frame it queues.

#include <array>
#include <atomic>
#include <bitset>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "dh3/bus/can_socket.hpp"
#include "dh3/base/fd_util.hpp"
#include "dh3/bus/bus.hpp"
#include "dh3/bus/link_tracker.hpp"

namespace dh3::bus {

struct SocketCanOptions {
  ReconnectOptions reconnect;
  /// The interface's bit rate when the user knows it (bit_rate()), e.g. 500000.
  std::uint32_t bit_rate = 0;
  /// Ask the kernel for each frame's receive timestamp (SO_TIMESTAMPNS) and
  /// hand them out through receive_times(): what a flight recorder writes.
  bool receive_timestamps = false;
};

/// The kinds an error frame (can_id with CAN_ERR_FLAG, 8 data bytes) reports,
/// bit i for ErrorFrameKind i. Pure, for the tests.
[[nodiscard]] std::bitset<kErrorFrameKinds> classify_error_frame(std::uint32_t can_id,
                                                                 const std::uint8_t* data);

class SocketCanBus final : public Bus {
 public:
  /// Opens `interface` (e.g. "can0"). Fails only for what cannot get better by
  /// waiting: no CAN support in the kernel, or an interface that exists but is
  /// not CAN. A missing or down interface gives a bus that is down and retries.
  static Result<std::unique_ptr<SocketCanBus>, std::string> open(std::string spec,
                                                                 std::string interface,
                                                                 const Clock& clock,
                                                                 SocketCanOptions options = {});

  /// The fd path with any opener; calls it once now and again to reconnect.
  SocketCanBus(std::string spec, CanSocketOpener opener, const Clock& clock,
               SocketCanOptions options = {});

  [[nodiscard]] const std::string& spec() const override { return spec_; }
  /// frame_invalid for ids over 0x7FF or lengths over 8; would_block when the
  /// kernel's transmit queue is full.
  Result<void, BusError> send(const CanFrame& frame) override;
  /// One sendmmsg() for all of them: the kernel queues them back to back
  /// before this thread can be preempted. Validates every frame first.
  Result<std::size_t, BusError> send_burst(std::span<const CanFrame> frames) override;
  /// Frames received before the link dropped are returned with success; the
  /// drop is reported by the next call.
  Result<void, BusError> receive(std::vector<CanFrame>& out, Duration timeout) override;
  void wake() override { wake_.wake(); }
  [[nodiscard]] LinkState link_state() const override { return tracker_.state(); }
  [[nodiscard]] std::uint32_t bit_rate() const override { return options_.bit_rate; }
  [[nodiscard]] BusDiagnostics diagnostics() const override;
  /// With SocketCanOptions::receive_timestamps; a frame the kernel did not
  /// stamp gets the wall clock's time of reading.
  [[nodiscard]] std::span<const WallTime> receive_times() const override { return receive_times_; }

  /// Diagnostics, read on the loop thread.
  struct Counters {
    std::uint64_t open_attempts = 0;
    std::uint64_t link_drops = 0;
    std::uint64_t frames_sent = 0;
    std::uint64_t frames_received = 0;
    /// Datagrams dropped in user space: extended or RTR frames, ids over 0xFF,
    /// lengths over 8, or not the size of a struct can_frame.
    std::uint64_t frames_ignored = 0;
    std::uint64_t error_frames = 0;  ///< controller error reports (CAN_ERR_FLAG)
  };
  [[nodiscard]] Counters counters() const;

 private:
  void try_open(TimePoint now);
  void go_down(std::string_view reason, TimePoint now);
  [[nodiscard]] bool can_carry_frames() const { return fd_.valid() && !bus_off_.load(); }
  void read_available(std::vector<CanFrame>& out, TimePoint now);
  void count_kernel_drops(std::uint32_t drops_so_far);
  void handle_error_frame(std::uint32_t can_id, const std::uint8_t* data, TimePoint now);
  void end_bus_off(std::string_view why);

  std::string spec_;
  CanSocketOpener opener_;
  const Clock& clock_;
  SocketCanOptions options_;
  LinkTracker tracker_;
  WakeFd wake_;
  UniqueFd fd_;
  std::uint64_t frames_sent_ = 0;
  std::uint64_t frames_received_ = 0;
  std::uint64_t error_frames_ = 0;
  /// The socket's SO_RXQ_OVFL figure when last seen (it counts per socket).
  std::uint32_t kernel_drops_seen_ = 0;
  /// When each kind was last logged, so a babbling bus cannot flood the log.
  std::array<std::optional<TimePoint>, kErrorFrameKinds> last_logged_{};
  // Read by diagnostics() from any thread.
  std::atomic<bool> bus_off_{false};
  std::array<std::atomic<std::uint64_t>, kErrorFrameKinds> error_kinds_{};
  std::atomic<std::uint64_t> rx_overflow_drops_{0};
  std::atomic<std::uint64_t> frames_ignored_{0};
  std::vector<WallTime> receive_times_;  ///< of the last receive()'s frames
};

}  // namespace dh3::bus
