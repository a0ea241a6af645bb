#pragma once
// What the hand layer tells the layers above it: commands, their results, each
// hand's state and the events that matter. Plain data; no DDS, no threads.

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dh3/base/clock.hpp"
#include "dh3/base/event_kind.hpp"
#include "dh3/base/result.hpp"
#include "dh3/protocol/registers.hpp"

namespace dh3::hand {

class GroupRelease;

/// Every command ends in exactly one of these (or OK).
enum class CommandError : std::uint8_t {
  invalid_argument,  ///< checked before anything is queued; never reaches the bus
  unknown_hand,      ///< no hand with that CAN ID on this bus
  timeout,           ///< the hand did not answer within the deadline (after retries)
  bus_down,          ///< the link to the bus is down, or went down while pending
  busy,              ///< the hand's command queue is full
  not_initialized,   ///< motion before initialization
  cancelled,         ///< superseded by a newer motion command, by stop, or shutdown
  failed,            ///< the hand answered, but not as required (e.g. init never finished)
};

[[nodiscard]] std::string_view to_string(CommandError error);

enum class CommandKind : std::uint8_t {
  initialize,         ///< enable init feedback, initialize, wait until finished
  move_to,            ///< value = position 0-100; OK when echoed (arrival is an event)
  set_closing_force,  ///< value = 20-100
  set_opening_force,  ///< value = 20-100
  rotate_to,          ///< value = 0-100; OK when echoed
  read_register,      ///< reg = any known register; OK with the value read
  write_register,     ///< reg + value; administrative registers (CAN ID, baud, 0x0801)
  grasp,              ///< value = closing force; OK with GraspOutcome once caught or missed
  release,            ///< value = position to open to; OK once arrived
  stop,               ///< hold the current position; cancels pending motion
};

[[nodiscard]] std::string_view to_string(CommandKind kind);

struct Command {
  CommandKind kind = CommandKind::read_register;
  std::int32_t value = 0;
  protocol::Register reg{};
  /// Overrides the bus's default deadline for this command when set.
  std::optional<Duration> timeout;
  /// Set for a member of a group command: its motion frame leaves with the
  /// other members' (group_release.hpp).
  std::shared_ptr<GroupRelease> group;
};

enum class GraspOutcome : std::uint8_t { none, grasped, missed };

struct CommandSuccess {
  std::int32_t value = 0;  ///< value read or written; for grasp, the final position
  GraspOutcome grasp = GraspOutcome::none;
};

using CommandResult = Result<CommandSuccess, CommandError>;

/// What the fingers are doing, as the service reports it. The grip outcomes
/// have the names the GRASP command's result and the events use (grasped,
/// missed, dropped); the hand's document calls status 3 "caught", a word
/// kept to the protocol layer.
enum class GripState : std::uint8_t {
  unknown,  ///< not read yet
  moving,   ///< status 0
  arrived,  ///< status 2, and the target was not a closing one
  grasped,  ///< status 3: holding an object
  missed,   ///< closed to the target without catching anything
  dropped,  ///< was grasped, status left 3 with no command sent
};

enum class RotationState : std::uint8_t { unknown, moving, arrived, blocked };

[[nodiscard]] std::string_view to_string(GripState state);
[[nodiscard]] std::string_view to_string(RotationState state);

/// One hand as the layer knows it. Published as-is by the layers above.
struct HandState {
  std::uint8_t can_id = 0;
  std::string name;  ///< from config, may be empty
  bool online = false;
  bool initialized = false;
  GripState grip = GripState::unknown;
  std::int32_t position = -1;         ///< last read, -1 before the first read
  std::int32_t target_position = -1;  ///< last written, -1 if none
  std::int32_t closing_force = -1;
  std::int32_t opening_force = -1;
  std::int32_t rotation = -1;
  std::int32_t rotation_target = -1;
  RotationState rotation_state = RotationState::unknown;
  std::int32_t firmware_version = 0;  ///< raw 0x1301 value (docs/protocol-notes.md reading 7)
  std::optional<CommandError> last_error;
  std::string last_error_message;
  std::uint64_t sequence = 0;  ///< increments on every change
  TimePoint updated_at{};
  /// When the hand last answered: the latest reply that went into these values
  /// (each register is read at its own pace, see poll_policy.hpp). Zero before
  /// the hand ever answered.
  TimePoint read_at{};
};

/// The events this layer makes: every kind of dh3/base/event_kind.hpp but
/// taken_over, which only the client library makes.
using EventKind = dh3::EventKind;

[[nodiscard]] std::string_view to_string(EventKind kind);

struct HandEvent {
  EventKind kind = EventKind::fault;
  std::uint8_t can_id = 0;
  TimePoint time{};
  /// ARRIVED, GRASPED, MISSED: where the fingers stopped; the rotation
  /// events: where the rotation stopped; empty when that was not read yet as
  /// the event went out (it goes out on the status read that shows the end,
  /// and the position is read in the next frame: the state published then
  /// says it). Read after the end when a rechecked arrival was confirmed by
  /// it, or when a read during the motion found the axis at its target.
  /// DROPPED: where the fingers held. Other events: the position as last
  /// read, empty before the first read.
  std::optional<std::int32_t> position;
  /// The target in force; for the end of a stop's hold, the target of the
  /// motion the stop ended.
  std::int32_t target = -1;
  std::int32_t value = 0;    ///< status value, force, or similar that explains it
  std::string message;
};

}  // namespace dh3::hand
