#pragma once
// Group commands: one command for several hands of one service, on one bus or
// several (Client::group()). All or none: the service checks every hand first
// (known, online, initialized where the command needs it, not leased by
// another client, value in range); if any fails, no hand is sent anything
// and the reply names each hand that failed and why (the others say
// CANCELLED). Otherwise the frames that start the hands' motions leave
// together: at one pass, back to back on a bus, once every hand's own
// command interval is clear, at one instant across the service's buses. One
// reply comes when the last hand's command has ended or timed out; each
// hand's events come as they do for single commands.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "dh3/export.hpp"
#include "dh3/types.hpp"

namespace dh3 {

enum class GroupCommand : std::uint8_t {
  initialize,         ///< value unused; each hand's result once it finished
  move,               ///< value = position 0-100
  rotate,             ///< value = 0-100 percent of 90 degrees
  grasp,              ///< value = closing force 20-100; each hand grasped or missed
  release,            ///< value = position to open to; once arrived
  set_closing_force,  ///< value = 20-100
  set_opening_force,  ///< value = 20-100
};
/// "INITIALIZE", "MOVE", ... as the wire spells the command.
DH3_CLIENT_API std::string_view to_string(GroupCommand command);

/// One hand's part of a group command.
struct GroupMemberReply {
  HandAddress hand;
  Code code = Code::ok;  ///< CANCELLED: another hand of the group failed first
  std::string message;
  std::int32_t value = 0;  ///< as Reply::value (GRASP: the final position)
  GraspOutcome grasp = GraspOutcome::none;

  [[nodiscard]] bool ok() const { return code == Code::ok; }
};

struct GroupReply {
  /// OK if every hand's is; else the first failed hand's (or the client's own:
  /// NO_SERVICE, NO_REPLY, SERVICE_LOST, NOT_CONNECTED, INVALID_ARGUMENT before
  /// sending).
  Code code = Code::ok;
  /// Every failed hand and why, for every code but OK.
  std::string message;
  /// In the order the hands were given (empty if the request never reached
  /// the service).
  std::vector<GroupMemberReply> hands;

  [[nodiscard]] bool ok() const { return code == Code::ok; }
  explicit operator bool() const { return ok(); }
};

}  // namespace dh3
