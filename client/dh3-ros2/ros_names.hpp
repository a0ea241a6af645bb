#pragma once
// ROS 2 names as dh3-ros2 uses them: a namespace and a name resolved to a
// fully qualified name under ROS's rules (tokens of letters, digits and
// underscores, none starting with a digit, no "__"), the DDS topic ROS's
// middlewares make of it ("rt/..."), and joint names made from a pattern.

#include <string>

#include "dh3/base/result.hpp"
#include "dh3/types.hpp"

namespace dh3::ros2 {

/// `name` inside `ros_namespace` ("/" or "/a/b"), or `name` itself when it
/// starts with "/": "/joint_states", "/cell/joint_states". The error says
/// which rule the name breaks.
[[nodiscard]] Result<std::string, std::string> resolve_name(const std::string& ros_namespace,
                                                            const std::string& name);

/// The DDS topic of a ROS topic: "/joint_states" -> "rt/joint_states".
[[nodiscard]] std::string topic_on_dds(const std::string& fully_qualified);

/// `pattern` with {service}, {bus} and {id} replaced by the hand's; characters
/// a ROS name token may not hold become '_'.
[[nodiscard]] std::string expand_hand_pattern(const std::string& pattern,
                                              const HandAddress& hand);

}  // namespace dh3::ros2
