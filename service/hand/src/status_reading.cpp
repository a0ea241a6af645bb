#include "status_reading.hpp"

#include <cstdlib>

namespace dh3::hand {
namespace {

bool near(std::int32_t position, std::int32_t target) {
  return position < 0 || target < 0 || std::abs(position - target) <= kArrivalTolerance;
}

GripReading finger_motion_ends(GripState grip, EventKind event) {
  GripReading reading;
  reading.grip = grip;
  reading.event = event;
  reading.motion_ended = true;
  return reading;
}

GripReading read_caught(const FingerView& view) {
  if (view.motion && !view.motion->closing) return GripReading{.stale = true};  // we are opening
  GripReading reading = view.motion ? finger_motion_ends(GripState::grasped, EventKind::grasped)
                                    : GripReading{.grip = GripState::grasped};
  reading.hold_starts = true;
  return reading;
}

GripReading read_moving_or_arrived(FingerStatus status, const FingerView& view) {
  if (view.grip == GripState::grasped && view.hold_untouched) {
    // The document's drop detection: status left 3 with no command sent.
    return GripReading{.grip = GripState::dropped, .event = EventKind::dropped};
  }
  if (view.grip == GripState::dropped && view.hold_untouched) return {};  // stays dropped
  if (status == FingerStatus::moving) {
    // Without a motion of ours, 0 is the hand's "default": nothing to report.
    return view.motion ? GripReading{.grip = GripState::moving} : GripReading{};
  }
  if (!view.motion) {
    return view.grip == GripState::missed ? GripReading{}
                                             : GripReading{.grip = GripState::arrived};
  }
  if (!view.motion->moving_seen && !near(view.position, view.motion->target)) {
    return GripReading{.stale = true};
  }
  return view.motion->gripping ? finger_motion_ends(GripState::missed, EventKind::missed)
                               : finger_motion_ends(GripState::arrived, EventKind::arrived);
}

}  // namespace

GripReading read_grip_status(std::int32_t status, const FingerView& view) {
  switch (static_cast<FingerStatus>(status)) {
    case FingerStatus::caught:
      return read_caught(view);
    case FingerStatus::moving:
    case FingerStatus::arrived:
      return read_moving_or_arrived(static_cast<FingerStatus>(status), view);
  }
  if (status == view.last_undefined) return {};
  return GripReading{.event = EventKind::fault};
}

RotationReading read_rotation_status(std::int32_t status, const RotationView& view) {
  switch (static_cast<RotationStatus>(status)) {
    case RotationStatus::moving:
      return view.motion ? RotationReading{.state = RotationState::moving} : RotationReading{};
    case RotationStatus::arrived:
      if (!view.motion) return RotationReading{.state = RotationState::arrived};
      if (!view.motion->moving_seen && !near(view.rotation, view.motion->target)) {
        return RotationReading{.stale = true};
      }
      return RotationReading{.state = RotationState::arrived,
                             .event = EventKind::rotation_arrived,
                             .motion_ended = true};
    case RotationStatus::blocked:
      if (!view.motion) return RotationReading{.state = RotationState::blocked};
      return RotationReading{.state = RotationState::blocked,
                             .event = EventKind::rotation_blocked,
                             .motion_ended = true};
  }
  if (status == view.last_undefined) return {};
  return RotationReading{.event = EventKind::fault};
}

}  // namespace dh3::hand
