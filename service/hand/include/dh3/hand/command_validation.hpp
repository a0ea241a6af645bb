#pragma once
// Checks a command before anything is queued: out-of-range values never reach
// the bus (docs/protocol-notes.md reading 12). Pure: safe from any thread.

#include <cstdint>
#include <optional>
#include <string>

#include "dh3/base/result.hpp"
#include "dh3/hand/hand_types.hpp"

namespace dh3::hand {

/// The hand layer's rules for a command, in the order validate() applies them.
enum class CommandRule : std::uint8_t {
  positive_timeout,
  id_zero,            ///< ID 0 only reads or sets the CAN ID (reading 10)
  value_range,        ///< a value the register does not take (reading 12)
  known_register,     ///< a read of a register the map does not have
  writable_register,  ///< a write the register does not take
  admin,              ///< CAN ID and baud-rate writes need `allow_admin` (reading 6)
  known_command,
};

struct ValidationFailure {
  CommandError error = CommandError::invalid_argument;
  std::string message;  ///< what is wrong and what was expected
  /// The rule it breaks, for a caller that says it in its own terms or
  /// answers it at its own turn (the DDS side: ID 0 in the contract's field
  /// names, administration as DENIED once the hand is known).
  CommandRule rule = CommandRule::known_command;
};

/// Fine when the command may be queued for the hand with `can_id`.
/// ID 0 ("whichever hand is there", reading 10) only reads or sets the CAN ID.
/// CAN ID and baud-rate writes need `allow_admin`.
[[nodiscard]] Result<void, ValidationFailure> validate(std::uint8_t can_id, const Command& command,
                                                       bool allow_admin);

/// True for the registers whose write only takes effect after a reboot and
/// which reply only once stored (reading 6).
[[nodiscard]] bool is_admin_register(protocol::Register reg);
/// True for a command that writes such a register: it needs `allow_admin`.
[[nodiscard]] bool is_admin_command(const Command& command);
/// True for the only commands that may address CAN ID 0, "whichever hand is
/// there" (docs/protocol-notes.md reading 10): reading or setting the CAN ID.
[[nodiscard]] bool may_address_id_zero(const Command& command);

/// Whether a command starts a finger motion, a rotation, or needs the hand
/// initialized (a motion, or a stop, which holds the axes where they are).
[[nodiscard]] bool moves_fingers(const Command& command);
[[nodiscard]] bool moves_rotation(const Command& command);
[[nodiscard]] bool needs_initialization(const Command& command);

}  // namespace dh3::hand
