#include "hand_actions.hpp"

#include <spdlog/spdlog.h>

#include "gripper_command_endpoints.hpp"
#include "parallel_gripper_endpoints.hpp"
#include "ros_names.hpp"

namespace dh3::ros2 {

HandActions::HandActions(RosParticipant& participant, Client& client, const Ros2Options& options,
                         std::function<void()> made)
    : participant_(participant), client_(client), options_(options), made_(std::move(made)) {}

std::optional<std::string> HandActions::name_of(const std::string& pattern,
                                                const HandAddress& hand) const {
  auto name = resolve_name(options_.ros_namespace, expand_hand_pattern(pattern, hand));
  if (!name) {
    spdlog::error("dh3-ros2: no {} for {}: {}", pattern, hand.to_string(), name.error());
    return std::nullopt;
  }
  return *name;
}

HandActions::Face HandActions::make_face(const HandAddress& hand) {
  Face face;
  auto turn = std::make_shared<HandTurn>();
  const auto& units = options_.units;
  if (auto action = name_of(options_.action, hand)) {
    face.gripper = std::make_unique<GripperActionServer>(
        participant_, client_, hand, *action, units, turn, [&](ActionEndpoints::Handlers h) {
          return std::make_unique<GripperCommandEndpoints>(participant_, *action, std::move(h));
        });
    if (!face.gripper->ok()) spdlog::error("dh3-ros2: Fast DDS refused an endpoint of {}", *action);
  }
  if (auto action = name_of(options_.parallel_action, hand)) {
    const auto finger = expand_hand_pattern(options_.joint_names.finger, hand);
    face.parallel = std::make_unique<GripperActionServer>(
        participant_, client_, hand, *action, units, turn, [&](ActionEndpoints::Handlers h) {
          return std::make_unique<ParallelGripperEndpoints>(participant_, *action, finger,
                                                            std::move(h));
        });
    if (!face.parallel->ok()) {
      spdlog::error("dh3-ros2: Fast DDS refused an endpoint of {}", *action);
    }
  }
  auto initialize = name_of(options_.initialize_service, hand);
  auto forces = name_of(options_.forces_service, hand);
  if (initialize && forces) {
    face.services = std::make_unique<HandServices>(participant_, client_, hand, *initialize,
                                                   *forces, units, turn);
    if (!face.services->ok()) {
      spdlog::error("dh3-ros2: Fast DDS refused an endpoint of {} or {}", *initialize, *forces);
    }
  }
  return face;
}

void HandActions::on_status(const HandStatus& status) {
  {
    std::lock_guard lock(mutex_);
    if (faces_.count(status.address) != 0) return;
    faces_[status.address] = make_face(status.address);  // tried once
    spdlog::info("dh3-ros2: serving {}", status.address.to_string());
  }
  if (made_) made_();
}

}  // namespace dh3::ros2
