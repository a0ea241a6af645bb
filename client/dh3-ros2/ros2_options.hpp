#pragma once
// dh3-ros2's command line: how it joins the DDS domain (the options of dh3ctl
// and dh3-web), its ROS 2 names and its units.

#include <optional>
#include <ostream>
#include <string>

#include "dh3/client.hpp"
#include "dh3/contract/participant_options.hpp"
#include "discovery_info.hpp"
#include "joint_state_message.hpp"
#include "joint_units.hpp"

namespace dh3::ros2 {

struct Ros2Options {
  ClientOptions client;
  /// The ROS namespace relative names resolve in.
  std::string ros_namespace = "/";
  /// The JointState topic, as a ROS name; resolved into `joint_states_dds`.
  std::string joint_states = "joint_states";
  std::string joint_states_dds;
  JointNames joint_names;
  /// Each hand's GripperCommand action, a ROS name pattern of {service},
  /// {bus} and {id}, resolved in the namespace.
  std::string action = "{service}_{bus}_{id}/gripper_cmd";
  /// Each hand's ParallelGripperCommand action, a pattern as `action`.
  std::string parallel_action = "{service}_{bus}_{id}/parallel_gripper_cmd";
  /// Each hand's std_srvs/srv/Trigger service that initializes it.
  std::string initialize_service = "{service}_{bus}_{id}/initialize";
  /// Each hand's rcl_interfaces/srv/SetParameters service for its forces.
  std::string forces_service = "{service}_{bus}_{id}/set_forces";
  /// The node ros_discovery_info announces, in `ros_namespace`, and the
  /// layout of its message (rmw's GID: 24 bytes in Humble, 16 in Jazzy).
  std::string node_name = "dh3_ros2";
  RosDistro ros_distro = RosDistro::jazzy;
  JointUnits units;
  std::string log_level = "info";
};

/// Fills `options` from the command line. nullopt: go on; a number: exit with
/// it (after --help, --version, or a bad option reported on `err`).
[[nodiscard]] std::optional<int> parse_ros2_options(int argc, const char* const* argv,
                                                    Ros2Options& options, std::ostream& out,
                                                    std::ostream& err);

/// The ROS 2 participant's transports, discovery and security: the client's.
/// Unlike the client's own participant it hears every participant, as ROS 2
/// nodes are not dh3 services.
[[nodiscard]] contract::ParticipantOptions ros_participant_options(const ClientOptions& client);

}  // namespace dh3::ros2
