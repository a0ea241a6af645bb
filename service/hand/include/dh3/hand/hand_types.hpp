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

/// What the fingers are doing, as the service reports it.
enum class GripState : std::uint8_t {
  unknown,    ///< not read yet
  moving,     ///< status 0
  arrived,    ///< status 2, and the target was not a closing one
  caught,     ///< status 3: holding an object
  no_object,  ///< closed to the target without catching anything
  dropped,    ///< was caught, status left 3 with no command sent
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

enum class EventKind : std::uint8_t {
  online,
  offline,
  initialized,
  init_failed,
  arrived,
  grasped,
  missed,
  dropped,
  rotation_arrived,
  rotation_blocked,
  fault,
};

[[nodiscard]] std::string_view to_string(EventKind kind);

struct HandEvent {
  EventKind kind = EventKind::fault;
  std::uint8_t can_id = 0;
  TimePoint time{};
  /// The position (the rotation, for the rotation events) as last read when
  /// the event went out: for an ending motion, where it started (the state
  /// published after the next read says where it stopped).
  std::int32_t position = -1;
  std::int32_t target = -1;  ///< the target in force
  std::int32_t value = 0;    ///< status value, force, or similar that explains it
  std::string message;
};

}  // namespace dh3::hand
