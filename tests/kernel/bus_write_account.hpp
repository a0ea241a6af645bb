#pragma once
// What the CAN recording (candump -L) says of the takeover test's commands:
// how often each command's write went to its hand. Every command writes a
// value its hand's register did not get from the command before, so a write
// frame (CAN ID, register, value) belongs to the latest command sent before
// it with that hand, register and value. On one vcan the recording cannot
// tell the service's frames from the hands': a hand echoes a write with the
// request's bytes, so a write sent once shows as two equal frames, request
// and echo, and one sent twice as four.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "kernel/command_log.hpp"

namespace dh3::test {

/// One frame of a `candump -L` log.
struct LoggedFrame {
  WallClock::time_point at;
  std::uint32_t can_id = 0;
  std::vector<std::uint8_t> data;
  std::string line;  ///< as candump wrote it
};

struct CandumpLog {
  std::vector<LoggedFrame> frames;  ///< every classic data frame, in order
  std::size_t dropped = 0;          ///< frames candump -d says its socket dropped
};

/// A `candump -L -d` file.
CandumpLog read_candump_log(const std::string& path);

struct BusWriteAccount {
  /// Per command (the log's order): how many times its write was sent.
  std::vector<std::size_t> sends;
  /// Per command: its write frames (indexes into the recording's frames).
  std::vector<std::vector<std::size_t>> frames_of;
  /// Per command: one of its write frames came after its first answer.
  std::vector<bool> sent_after_answer;
  /// Write frames from the first command on that no command asked for (a
  /// hand initialized again, a value re-sent by the new owner on its own).
  std::vector<LoggedFrame> unasked;
  std::size_t frames = 0;  ///< frames in the recording from the first command on
};

/// Which command each write frame from the first command's sending on
/// belongs to, and so how often each command was sent.
BusWriteAccount account_writes(const std::vector<LoggedCommand>& commands,
                               const std::vector<LoggedFrame>& frames);

}  // namespace dh3::test
