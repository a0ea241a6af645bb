// dh3-ros2: the hands of a DDS domain as ROS 2 sees a gripper, without
// linking ROS 2. A client of the domain like dh3ctl and dh3-web, with a second
// participant that follows ROS 2's conventions on DDS (docs/ros2.md).

#include <spdlog/spdlog.h>

#include <csignal>
#include <iostream>

#include "dh3/base/stop_signals.hpp"
#include "dh3/client.hpp"
#include "discovery_info.hpp"
#include "hand_actions.hpp"
#include "joint_state_publisher.hpp"
#include "ros2_options.hpp"
#include "ros_participant.hpp"

int main(int argc, char** argv) {
  const sigset_t signals = dh3::block_stop_signals();

  dh3::ros2::Ros2Options options;
  if (auto exit_code = dh3::ros2::parse_ros2_options(argc, argv, options, std::cout, std::cerr)) {
    return *exit_code;
  }
  spdlog::set_level(spdlog::level::from_str(options.log_level));

  auto participant =
      dh3::ros2::RosParticipant::create(dh3::ros2::ros_participant_options(options.client));
  if (!participant) {
    std::cerr << "dh3-ros2: " << participant.error() << "\n";
    return 1;
  }
  // First, so that its own writer is the one it leaves out.
  auto discovery = dh3::ros2::DiscoveryInfoPublisher::create(
      **participant, options.ros_distro, options.ros_namespace, options.node_name);
  if (!discovery) {
    std::cerr << "dh3-ros2: " << discovery.error() << "\n";
    return 1;
  }
  auto joint_states = dh3::ros2::JointStatePublisher::create(
      **participant, options.joint_states_dds, options.joint_names, options.units);
  if (!joint_states) {
    std::cerr << "dh3-ros2: " << joint_states.error() << "\n";
    return 1;
  }
  dh3::Client client(options.client);
  if (!client.connected()) {
    std::cerr << "dh3-ros2: " << client.error() << "\n";
    return 1;
  }
  (*discovery)->publish();
  dh3::ros2::HandActions actions(**participant, client, options, [&discovery] {
    if (!(*discovery)->publish()) spdlog::warn("dh3-ros2: ros_discovery_info was not written");
  });
  auto statuses = client.subscribe_status([&](const dh3::HandStatus& status) {
    actions.on_status(status);
    if (!joint_states->on_status(status)) {
      spdlog::warn("dh3-ros2: the joint state of {} was not written", status.address.to_string());
    }
  });
  // One line on stdout for people and for scripts that start it.
  std::cout << "dh3-ros2: publishing joint states on " << options.joint_states_dds
            << " and per hand the actions " << options.action << " and " << options.parallel_action
            << " (domain " << options.client.domain << ")" << std::endl;

  int signal_number = 0;
  sigwait(&signals, &signal_number);
  spdlog::info("dh3-ros2: signal {}, stopping", signal_number);
  statuses.unsubscribe();
  return 0;
}
