#pragma once
// A hand's status as a sensor_msgs/JointState: two joints per hand, the
// fingers' opening and the rotation of the rotating finger base, in the units
// JointUnits says. Pure: no DDS entities, no clock.

#include <string>

#include "dh3/types.hpp"
#include "joint_units.hpp"
#include "ros2_interfaces.h"

namespace dh3::ros2 {

/// The joint names, as patterns of {service}, {bus} and {id}.
struct JointNames {
  std::string finger = "{service}_{bus}_{id}_finger_joint";
  std::string rotation = "{service}_{bus}_{id}_rotation_joint";
};

/// The message for one hand. Positions not read yet are NaN. Effort: the
/// finger joint's is the closing force set while the fingers hold an object,
/// 0 while they hold nothing, NaN while they move or their state is unknown;
/// the rotation joint's is NaN (the hand reports none), as ROS 2's
/// joint_state_broadcaster reports an interface it lacks. Velocity is empty.
/// The stamp is when the values were read from the hand (the status's
/// timestamp before the hand ever answered).
[[nodiscard]] sensor_msgs::msg::dds_::JointState_ joint_state_of(const HandStatus& status,
                                                                 const JointNames& names,
                                                                 const JointUnits& units);

}  // namespace dh3::ros2
