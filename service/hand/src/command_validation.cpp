#include "dh3/hand/command_validation.hpp"

#include <fmt/format.h>

namespace dh3::hand {
namespace {

Failure<ValidationFailure> invalid(CommandRule rule, std::string message) {
  return fail(ValidationFailure{CommandError::invalid_argument, std::move(message), rule});
}

Result<void, ValidationFailure> check_value(protocol::Register reg, std::int32_t value,
                                            std::string_view what) {
  const auto range = protocol::write_range(reg);
  if (range && !range->contains(value)) {
    return invalid(CommandRule::value_range, fmt::format("{} {} is out of range (expected {}-{})",
                                                         what, value, range->min, range->max));
  }
  return {};
}

}  // namespace

bool is_admin_register(protocol::Register reg) {
  return reg == protocol::reg::kCanId || reg == protocol::reg::kBaudRate;
}

bool is_admin_command(const Command& command) {
  return command.kind == CommandKind::write_register && is_admin_register(command.reg);
}

bool may_address_id_zero(const Command& command) {
  return (command.kind == CommandKind::read_register ||
          command.kind == CommandKind::write_register) &&
         command.reg == protocol::reg::kCanId;
}

Result<void, ValidationFailure> validate(std::uint8_t can_id, const Command& command,
                                         bool allow_admin) {
  namespace reg = protocol::reg;
  if (command.timeout && *command.timeout <= Duration::zero()) {
    return invalid(CommandRule::positive_timeout, "timeout must be positive");
  }
  if (can_id == 0 && !may_address_id_zero(command)) {
    return invalid(
        CommandRule::id_zero,
        "CAN ID 0 addresses whichever hand is there: only reading or setting the CAN ID");
  }
  switch (command.kind) {
    case CommandKind::initialize:
    case CommandKind::stop:
      return {};
    case CommandKind::move_to:
      return check_value(reg::kPosition, command.value, "position");
    case CommandKind::release:
      return check_value(reg::kPosition, command.value, "release position");
    case CommandKind::rotate_to:
      return check_value(reg::kRotation, command.value, "rotation");
    case CommandKind::set_closing_force:
      return check_value(reg::kClosingForce, command.value, "closing force");
    case CommandKind::set_opening_force:
      return check_value(reg::kOpeningForce, command.value, "opening force");
    case CommandKind::grasp:
      return check_value(reg::kClosingForce, command.value, "grasp force");
    case CommandKind::read_register:
      if (!protocol::is_known(command.reg)) {
        return invalid(
            CommandRule::known_register,
            fmt::format("register 0x{:04X} is not in the DH-3 register map", command.reg.code()));
      }
      return {};
    case CommandKind::write_register: {
      if (const auto written = protocol::check_write(command.reg, command.value); !written) {
        const auto range = protocol::write_range(command.reg);
        if (written.error() == protocol::RegisterError::out_of_range && range) {
          return invalid(
              CommandRule::value_range,
              fmt::format("{} {} is out of range (expected {}-{})", protocol::name(command.reg),
                          command.value, range->min, range->max));
        }
        return invalid(CommandRule::writable_register,
                       fmt::format("cannot write register 0x{:04X}: {}", command.reg.code(),
                                   protocol::to_string(written.error())));
      }
      if (is_admin_command(command) && !allow_admin) {
        return invalid(CommandRule::admin,
                       fmt::format("writing {} is administrative and not allowed on this bus",
                                   protocol::name(command.reg)));
      }
      return {};
    }
  }
  return invalid(CommandRule::known_command, "unknown command");
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
