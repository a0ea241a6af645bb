#include "hand_driver_states.hpp"

namespace dh3::hand {

JobStep first_step(CommandKind kind) {
  switch (kind) {
    case CommandKind::initialize:
      return InitializeStep::enable_feedback;
    case CommandKind::grasp:
      return GraspStep::set_force;
    case CommandKind::stop:
      return StopStep::read_position;
    default:
      return SingleFrame{};
  }
}

}  // namespace dh3::hand
