#include "dh3/hand/hand_driver_states.hpp"

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

bool moves_fingers(const Command& command) {
  switch (command.kind) {
    case CommandKind::move_to:
    case CommandKind::grasp:
    case CommandKind::release:
      return true;
    case CommandKind::write_register:
      return command.reg == protocol::reg::kPosition;
    default:
      return false;
  }
}

bool moves_rotation(const Command& command) {
  return command.kind == CommandKind::rotate_to ||
         (command.kind == CommandKind::write_register && command.reg == protocol::reg::kRotation);
}

bool needs_initialization(const Command& command) {
  return moves_fingers(command) || moves_rotation(command) || command.kind == CommandKind::stop;
}

}  // namespace dh3::hand
