#include "hand_actions.hpp"

#include <spdlog/spdlog.h>

#include "ros_names.hpp"

namespace dh3::ros2 {

HandActions::HandActions(RosParticipant& participant, Client& client, std::string ros_namespace,
                         std::string pattern, JointUnits units)
    : participant_(participant),
      client_(client),
      ros_namespace_(std::move(ros_namespace)),
      pattern_(std::move(pattern)),
      units_(units) {}

void HandActions::on_status(const HandStatus& status) {
  std::lock_guard lock(mutex_);
  if (servers_.count(status.address) != 0) return;
  auto action = resolve_name(ros_namespace_, expand_hand_pattern(pattern_, status.address));
  if (!action) {
    spdlog::error("dh3-ros2: no action for {}: {}", status.address.to_string(), action.error());
    servers_[status.address] = nullptr;  // said once
    return;
  }
  auto server =
      std::make_unique<GripperActionServer>(participant_, client_, status.address, *action, units_);
  if (!server->ok()) {
    spdlog::error("dh3-ros2: Fast DDS refused an endpoint of {}", *action);
  } else {
    spdlog::info("dh3-ros2: {} serves {}", *action, status.address.to_string());
  }
  servers_[status.address] = std::move(server);
}

}  // namespace dh3::ros2
