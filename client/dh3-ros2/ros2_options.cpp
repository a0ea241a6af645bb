#include "ros2_options.hpp"

#include <CLI/CLI.hpp>

#include "client_options_cli.hpp"
#include "dh3/base/version.hpp"
#include "ros_names.hpp"

namespace dh3::ros2 {

namespace {

void add_unit_options(CLI::App& app, JointUnits& units) {
  app.add_option("--units", units.raw_percent,
                 "si: meters, radians and newtons (default); percent: the hand's own percent")
      ->transform(
          CLI::CheckedTransformer(std::map<std::string, bool>{{"si", false}, {"percent", true}}));
  app.add_option("--opening-max", units.opening_max_m,
                 "the opening between the fingers at 100 %, in meters (default 0.095, from "
                 "DH's ROS 1 driver: check it against your hand)")
      ->check(CLI::PositiveNumber);
  app.add_option("--force-max", units.force_max_n,
                 "the force at 100 %, in newtons (default 90, from DH's ROS 1 driver)")
      ->check(CLI::PositiveNumber);
  app.add_option("--rotation-min", units.rotation_min_rad,
                 "the rotation joint at 0 %, in radians (default 0)");
  app.add_option("--rotation-max", units.rotation_max_rad,
                 "the rotation joint at 100 %, in radians (default pi/2: the protocol's 90 "
                 "degrees)");
}

}  // namespace

std::optional<int> parse_ros2_options(int argc, const char* const* argv, Ros2Options& options,
                                      std::ostream& out, std::ostream& err) {
  CLI::App app{
      "dh3-ros2: the DH-3 hands of a DDS domain as ROS 2 sees a gripper: sensor_msgs/JointState "
      "on a joint_states topic and per hand the control_msgs/action/GripperCommand and "
      "ParallelGripperCommand actions and initialize and set_forces services, and a node in "
      "ros_discovery_info, without linking ROS 2 (docs/ros2.md)."};
  app.name("dh3-ros2");
  app.set_version_flag("--version", kVersion);
  app.add_option("--namespace", options.ros_namespace,
                 "the ROS namespace relative names resolve in (default /)");
  app.add_option("--joint-states", options.joint_states,
                 "the JointState topic, a ROS name (default joint_states)");
  app.add_option("--finger-joint", options.joint_names.finger,
                 "each hand's finger joint (the opening), a pattern of {service}, {bus} and {id} "
                 "(default {service}_{bus}_{id}_finger_joint)");
  app.add_option("--rotation-joint", options.joint_names.rotation,
                 "each hand's rotation joint (default {service}_{bus}_{id}_rotation_joint)");
  app.add_option("--action", options.action,
                 "each hand's control_msgs/action/GripperCommand action, a pattern of {service}, "
                 "{bus} and {id} (default {service}_{bus}_{id}/gripper_cmd)");
  app.add_option("--parallel-action", options.parallel_action,
                 "each hand's control_msgs/action/ParallelGripperCommand action, a pattern "
                 "(default {service}_{bus}_{id}/parallel_gripper_cmd)");
  app.add_option("--initialize-service", options.initialize_service,
                 "each hand's std_srvs/srv/Trigger service that initializes it, a pattern "
                 "(default {service}_{bus}_{id}/initialize)");
  app.add_option("--forces-service", options.forces_service,
                 "each hand's rcl_interfaces/srv/SetParameters service for closing_force and "
                 "opening_force, a pattern (default {service}_{bus}_{id}/set_forces)");
  app.add_option("--node-name", options.node_name,
                 "the node ros_discovery_info announces (default dh3_ros2)");
  app.add_option("--ros-distro", options.ros_distro,
                 "jazzy (default) or humble: the layout of ros_discovery_info (rmw's GID is 16 "
                 "bytes in Jazzy, 24 in Humble)")
      ->transform(CLI::CheckedTransformer(std::map<std::string, RosDistro>{
          {"jazzy", RosDistro::jazzy}, {"humble", RosDistro::humble}}));
  add_unit_options(app, options.units);
  ctl::add_log_level_option(app, options.log_level);
  ctl::add_client_options(app, options.client);
  if (auto code = ctl::parse_command_line(app, argc, argv, out, err)) return code;
  auto topic = resolve_name(options.ros_namespace, options.joint_states);
  if (!topic) {
    err << "dh3-ros2: --joint-states: " << topic.error() << "\n";
    return 2;
  }
  options.joint_states_dds = topic_on_dds(*topic);
  if (auto node = resolve_name(options.ros_namespace, options.node_name);
      !node || options.node_name.find('/') != std::string::npos) {
    err << "dh3-ros2: --node-name: " << (node ? "a node name holds no '/'" : node.error()) << "\n";
    return 2;
  }
  options.client.participant_name = "dh3-ros2";
  return std::nullopt;
}

contract::ParticipantOptions ros_participant_options(const ClientOptions& client) {
  auto options = contract::participant_options_of(client);
  options.name = "dh3_ros2";
  return options;
}

}  // namespace dh3::ros2
