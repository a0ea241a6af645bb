#pragma once
// Every command the takeover test's clients send, and every answer each one
// got, with the wall-clock times the CAN recording (candump -L, the kernel's
// realtime timestamps) is compared with. Written by the client threads and
// their completion callbacks at once; read after the run.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "dh3/types.hpp"

namespace dh3::test {

using WallClock = std::chrono::system_clock;

/// One command: which hand, which register it writes with which value, when
/// it was sent and each answer it got (exactly one, if all is well).
struct LoggedCommand {
  struct Answer {
    Code code = Code::ok;
    std::string message;
    WallClock::time_point at;
  };
  int client = 0;
  std::uint16_t can_id = 0;
  std::uint16_t register_code = 0;  ///< function << 8 | sub-function, as on the wire
  std::int32_t value = 0;
  WallClock::time_point sent;
  std::vector<Answer> answers;
};

class CommandLog {
 public:
  /// Records a command about to be sent; its index for answer().
  std::size_t sent(int client, std::uint16_t can_id, std::uint16_t register_code,
                   std::int32_t value);
  /// Records an answer to command `index` (called from a completion callback).
  void answer(std::size_t index, const Reply& reply);
  /// How many answers command `index` has got so far.
  [[nodiscard]] std::size_t answers(std::size_t index) const;
  /// Each of clients 0 to `clients` - 1 had a command sent after `since`
  /// answered OK.
  [[nodiscard]] bool each_answered_ok_since(WallClock::time_point since, int clients) const;
  /// A copy of every command so far.
  [[nodiscard]] std::vector<LoggedCommand> commands() const;

 private:
  mutable std::mutex mutex_;
  std::vector<LoggedCommand> commands_;
};

}  // namespace dh3::test
