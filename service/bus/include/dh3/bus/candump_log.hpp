#pragma once
// can-utils' candump log format, one frame a line, as `candump -l -x` writes it
// and canplayer, log2asc and candump's other readers take it:
//
//   (1700000000.123456) bus0 001#0102030405060708 T
//
// the wall-clock time in seconds with six decimals, the device (here the bus's
// name), the standard 11-bit ID in three hex digits, '#', the data bytes in
// hex, and the direction: T for a frame the service sent, R for one it
// received (can-utils' readers take the line with or without it). Pure.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "dh3/base/result.hpp"
#include "dh3/bus/bus.hpp"

namespace dh3::bus {

enum class FrameDirection : std::uint8_t { received, sent };

/// One frame on a bus, as the flight recorder keeps it.
struct LoggedFrame {
  WallTime time{};
  FrameDirection direction = FrameDirection::received;
  CanFrame frame;
};

/// One line of a log read back.
struct LogLine {
  WallTime time{};  ///< to the microsecond
  std::string device;
  CanFrame frame;
  std::optional<FrameDirection> direction;  ///< nullopt: the line has no T/R field
};

enum class LogLineError : std::uint8_t {
  not_a_frame,  ///< a comment, a blank line or candump's DROPCOUNT note: skip it
  malformed,    ///< starts like a frame but is not one
  unsupported,  ///< a frame DH-3 hands never send: extended, remote, CAN FD, error
};

[[nodiscard]] std::string_view to_string(LogLineError error);

/// A name that can stand as the log's device field: a bus name with anything
/// but letters, digits, '-', '_' and '.' replaced by '_' (the readers split
/// lines at blanks).
[[nodiscard]] std::string log_device_name(std::string_view bus);

/// The line for `frame` on `device` (log_device_name() already applied),
/// with its direction field, ending in '\n'.
[[nodiscard]] std::string format_log_line(const LoggedFrame& frame, std::string_view device);

/// Reads one line (with or without its '\n').
[[nodiscard]] Result<LogLine, LogLineError> parse_log_line(std::string_view line);

}  // namespace dh3::bus
