#pragma once
// One interface to every way of reaching DH-3 hands: a CAN frame out, CAN frames
// in. Backends: socketcan (Linux PF_CAN), transfer_box (the vendor's box over
// TCP or a serial line) and sim (in-process simulated hands).
//
// Threading: one I/O loop owns a Bus and is the only caller of send() and
// receive(); wake() and diagnostics() may be called from any thread.

#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "dh3/base/clock.hpp"
#include "dh3/base/result.hpp"

namespace dh3::bus {

/// A classic CAN 2.0A frame. DH-3 messages always use 8 data bytes.
struct CanFrame {
  std::uint32_t id = 0;  ///< 11-bit identifier = the hand's CAN ID
  std::uint8_t length = 8;
  std::array<std::uint8_t, 8> data{};

  friend bool operator==(const CanFrame&, const CanFrame&) = default;
};

/// A moment by the wall clock, as the kernel stamps received frames and as
/// candump logs carry them (seconds since the Unix epoch).
using WallTime = std::chrono::system_clock::time_point;

enum class BusError : std::uint8_t {
  link_down,      ///< not connected (cable out, box unreachable, interface down)
  io_error,       ///< the OS refused a read or write on a live link
  frame_invalid,  ///< id over 0x7FF (or over 255 for a transfer box), length over 8
  would_block,    ///< the send buffer is full; try again after receive()
  not_permitted,  ///< a standby's bus (StandbyBus): it sends nothing until promoted
};

[[nodiscard]] std::string_view to_string(BusError error);

enum class LinkState : std::uint8_t { up, down };

/// What a CAN controller reports in error frames (linux/can/error.h classes);
/// one error frame may report several.
enum class ErrorFrameKind : std::uint8_t {
  bus_off,              ///< the controller left the bus: nothing goes out until it restarts
  error_passive,        ///< error counters over 127 (rx or tx)
  error_warning,        ///< error counters over 95 (rx or tx)
  error_active,         ///< back to normal after passive or warning
  controller_overflow,  ///< the controller's own rx/tx buffer overflowed
  restarted,            ///< the controller restarted after bus-off
  tx_timeout,           ///< a frame could not be sent in time
  lost_arbitration,
  protocol_violation,   ///< bit, form, stuff errors (with berr-reporting on)
  transceiver,          ///< wiring fault seen by the transceiver
  no_ack,               ///< nobody acknowledged a frame: no other node on the bus
  bus_error,            ///< a bus error without further class
};
inline constexpr std::size_t kErrorFrameKinds = 12;
[[nodiscard]] std::string_view to_string(ErrorFrameKind kind);

/// What a bus's flight recorder (FrameRecorder) did since it was made.
struct RecorderFigures {
  std::uint64_t frames_recorded = 0;  ///< written to a file
  /// Dropped because the writer fell behind and the queue was full, or
  /// because the file could not be written.
  std::uint64_t frames_dropped = 0;
  std::uint64_t bytes_written = 0;
  std::uint64_t files_opened = 0;  ///< the first file and each rotation
  std::uint64_t write_errors = 0;  ///< files that could not be opened or written
  /// Recording stopped by a write error (a full disk) until a write succeeds.
  bool stopped = false;
};

/// What a backend sees beneath the frames it delivers, counted since it was
/// made. Only a backend on a CAN controller (SocketCAN) sees these.
struct BusDiagnostics {
  bool sees_controller = false;  ///< false: every figure below is unknown, not 0
  bool bus_off = false;          ///< the controller is bus-off now
  std::array<std::uint64_t, kErrorFrameKinds> error_frames{};  ///< by ErrorFrameKind
  /// Frames the kernel dropped because the socket's receive queue was full.
  std::uint64_t rx_overflow_drops = 0;
  /// Frames no DH-3 hand sends that reached the backend anyway (extended,
  /// RTR, id over 0xFF, length over 8, bad size); the kernel filter keeps most
  /// of them out unseen.
  std::uint64_t frames_ignored = 0;
  /// The bus's flight recorder's figures; nullopt: the bus is not recorded.
  std::optional<RecorderFigures> recorder;
};

class Bus {
 public:
  virtual ~Bus() = default;
  Bus() = default;
  Bus(const Bus&) = delete;
  Bus& operator=(const Bus&) = delete;

  /// The spec this bus was opened from, e.g. "tcp:127.0.0.1:9000".
  [[nodiscard]] virtual const std::string& spec() const = 0;

  /// Sends one frame. Never blocks. link_down when the link is down.
  virtual Result<void, BusError> send(const CanFrame& frame) = 0;

  /// Sends `frames` back to back, in order (a group command's frames), and
  /// says how many it took: all, or the first few when the send buffer
  /// filled or a frame was invalid (the caller offers the rest again). Fails,
  /// having sent none, when not even the first was taken. Never blocks. The
  /// default sends them one by one; SocketCAN hands them to the kernel in one
  /// system call, so nothing else runs between them on this machine.
  virtual Result<std::size_t, BusError> send_burst(std::span<const CanFrame> frames);

  /// Waits at most `timeout` (0: do not wait) for frames and appends every one
  /// received to `out`. Backends that reconnect try to bring the link back up
  /// here, with backoff, and report link_down meanwhile. Returns early on wake().
  virtual Result<void, BusError> receive(std::vector<CanFrame>& out, Duration timeout) = 0;

  /// When each frame the last receive() appended was received, in the order it
  /// appended them: the kernel's receive timestamp where the backend has one
  /// (SocketCAN with SocketCanOptions::receive_timestamps). Empty when the
  /// backend keeps no times; then the caller's own clock is as good as any.
  [[nodiscard]] virtual std::span<const WallTime> receive_times() const { return {}; }

  /// Makes a blocked receive() (or the next one) return at once. Any thread.
  virtual void wake() = 0;

  [[nodiscard]] virtual LinkState link_state() const = 0;

  /// Line rate in bits per second when the backend knows it (CAN bit rate),
  /// 0 otherwise. Used for bus-load figures.
  [[nodiscard]] virtual std::uint32_t bit_rate() const { return 0; }

  /// Controller and kernel-queue figures; any thread. Default: sees nothing.
  [[nodiscard]] virtual BusDiagnostics diagnostics() const { return {}; }
};

}  // namespace dh3::bus
