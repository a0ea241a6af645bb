#pragma once
// How the values of the two status registers (0x0F01 fingers, 0x0F02 rotation)
// are read against what the driver knows: pure functions, no clock, no I/O.
//
// Fingers (docs/protocol-notes.md reading 2 for where the value sits):
// - 3 "caught" ends a closing motion with a catch (grasped); during an opening
//   motion it is a stale reading from before the command and ignored.
// - 0 or 2 while holding a catch with no finger command since is a drop; after
//   a drop nothing changes until the next finger command.
// - 2 "arrived" ends a motion: a grasp or a move to 0 with nothing caught is a
//   miss, any other an arrival. Before any 0 of the motion and far from the
//   target as last read, it may be a stale reading from before the command
//   (the caller then reads the position to tell). Without a motion it only
//   says the fingers are at rest.
// - 0 is "moving" during a motion and the hand's "default" otherwise.
// Rotation: 0 moving, 2 arrived (after a 0, or near the target, else stale), 3 blocked.
// Any other value is a fault, unless it is the one last reported on that axis
// (`last_undefined`, which the caller keeps).

#include <cstdint>
#include <optional>

#include "dh3/hand/hand_types.hpp"
#include "dh3/protocol/registers.hpp"
#include "hand_driver_states.hpp"

namespace dh3::hand {

/// A status 2 only counts as arrival at the new target when the position read
/// is this close to it (percent); otherwise it is a stale reading.
inline constexpr std::int32_t kArrivalTolerance = 3;

/// The values of 0x0F01 and 0x0F02, as the protocol layer's register map
/// declares them.
using FingerStatus = protocol::GripStatus;
using RotationStatus = protocol::RotationStatus;

/// What the driver knows of the fingers when a status value comes in.
struct FingerView {
  GripState grip = GripState::unknown;
  std::optional<FingerMotion> motion;
  /// Holding a catch with no finger command sent since.
  bool hold_untouched = false;
  std::int32_t position = -1;  ///< last read, -1 unknown
  /// The last value outside the document reported on this axis (0: none).
  std::int32_t last_undefined = 0;
};

/// What a finger status value means.
struct GripReading {
  std::optional<GripState> grip{};  ///< the fingers' new state, if it changes
  /// grasped, missed, arrived: the motion ended (reported once the position is
  /// read afresh); dropped, fault: at once.
  std::optional<EventKind> event{};
  bool motion_ended = false;
  bool hold_starts = false;  ///< a catch: the hold is untouched until the next finger command
  bool stale = false;        ///< from before the running motion: ignored
  friend bool operator==(const GripReading&, const GripReading&) = default;
};

[[nodiscard]] GripReading read_grip_status(std::int32_t status, const FingerView& view);

/// What the driver knows of the rotation when a status value comes in.
struct RotationView {
  std::optional<RotationMotion> motion;
  std::int32_t rotation = -1;  ///< last read, -1 unknown
  std::int32_t last_undefined = 0;
};

/// What a rotation status value means.
struct RotationReading {
  std::optional<RotationState> state{};  ///< the rotation's new state, if it changes
  std::optional<EventKind> event{};      ///< rotation_arrived, rotation_blocked or fault
  bool motion_ended = false;
  bool stale = false;
  friend bool operator==(const RotationReading&, const RotationReading&) = default;
};

[[nodiscard]] RotationReading read_rotation_status(std::int32_t status, const RotationView& view);

}  // namespace dh3::hand
