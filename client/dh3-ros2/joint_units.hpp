#pragma once
// How dh3-ros2 turns the hand's percent into the SI units ROS expects, and
// back for goals. No DH-3 datasheet was in reach: the defaults come from DH's
// ROS 1 driver (dh_gripper_ros clamps the DH-3's opening to 0-95 mm and its
// force to 15-90 N) and the protocol document (rotation 0-100 % of 90
// degrees); docs/ros2.md says where each comes from. A user checks them
// against the hand and sets them.

#include <cstdint>
#include <optional>

namespace dh3::ros2 {

struct JointUnits {
  /// Publish and accept the hand's own percent instead of SI units.
  bool raw_percent = false;
  /// The opening between the fingers at 100 % (fully open), in meters.
  double opening_max_m = 0.095;
  /// The force at 100 %, in newtons.
  double force_max_n = 90.0;
  /// The rotation joint at 0 % and at 100 %, in radians.
  double rotation_min_rad = 0.0;
  double rotation_max_rad = 1.5707963267948966;

  /// The opening for a position of `percent` (0 closed - 100 open).
  [[nodiscard]] double opening(std::int32_t percent) const;
  [[nodiscard]] double force(std::int32_t percent) const;
  [[nodiscard]] double rotation(std::int32_t percent) const;
  /// The hand's position percent for an opening, rounded; nullopt when it is
  /// NaN or outside 0-100 %.
  [[nodiscard]] std::optional<std::int32_t> opening_percent(double opening) const;
  /// The force percent for a force, rounded; nullopt when NaN or outside 0-100 %.
  [[nodiscard]] std::optional<std::int32_t> force_percent(double force) const;
};

}  // namespace dh3::ros2
