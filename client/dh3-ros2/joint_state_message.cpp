#include "joint_state_message.hpp"

#include <limits>

#include "ros_names.hpp"

namespace dh3::ros2 {

namespace {

constexpr double kUnknown = std::numeric_limits<double>::quiet_NaN();
constexpr std::uint64_t kNanosPerSecond = 1'000'000'000;

double finger_effort(const HandStatus& status, const JointUnits& units) {
  switch (status.grip) {
    case GripState::grasped:
      return units.force(status.closing_force);
    case GripState::arrived:
    case GripState::missed:
    case GripState::dropped:
      return 0.0;
    case GripState::moving:
    case GripState::unknown:
      break;
  }
  return kUnknown;
}

}  // namespace

sensor_msgs::msg::dds_::JointState_ joint_state_of(const HandStatus& status,
                                                   const JointNames& names,
                                                   const JointUnits& units) {
  sensor_msgs::msg::dds_::JointState_ message;
  const std::uint64_t at = status.read_at_ns != 0 ? status.read_at_ns : status.timestamp_ns;
  message.header().stamp().sec(static_cast<std::int32_t>(at / kNanosPerSecond));
  message.header().stamp().nanosec(static_cast<std::uint32_t>(at % kNanosPerSecond));
  message.name({expand_hand_pattern(names.finger, status.address),
                expand_hand_pattern(names.rotation, status.address)});
  message.position({status.position < 0 ? kUnknown : units.opening(status.position),
                    status.rotation < 0 ? kUnknown : units.rotation(status.rotation)});
  message.effort({finger_effort(status, units), kUnknown});
  return message;
}

}  // namespace dh3::ros2
