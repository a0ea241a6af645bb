#pragma once
// Checks a command request before anything reaches a bus (out-of-range values
// never do: docs/protocol-notes.md reading 12) and turns it into what the hand
// layer or the lease table needs. Every rejection carries the code and a
// message that says what was wrong.

#include <cstdint>
#include <string>

#include "dh3/base/result.hpp"
#include "dh3/contract/dh3.h"
#include "dh3/hand/hand_types.hpp"
#include "hand_directory.hpp"

namespace dh3::dds {

enum class RequestAction : std::uint8_t {
  hand_command,  ///< goes to the bus's scheduler
  scan,          ///< probe the bus for hands
  acquire_lease,
  renew_lease,
  release_lease,
};

struct ValidRequest {
  RequestAction action = RequestAction::hand_command;
  std::uint16_t bus = 0;
  std::uint8_t can_id = 0;
  hand::Command command;  ///< for hand_command
  Duration lease_ttl{};   ///< for acquire_lease and renew_lease
  /// Motion and write commands: refused while another client holds the lease.
  bool needs_lease = false;
};

struct Rejection {
  msg::ResultCode code = msg::INVALID_ARGUMENT;
  std::string message;
};

/// Whether an administrative command (SET_CAN_ID, SET_BAUD_RATE) may run.
enum class AdminAccess : std::uint8_t {
  allowed,
  off,       ///< the service does not allow them (allow_admin off)
  elsewhere  ///< under DDS Security they are taken only from the admin request topic
};

/// Validates a request addressed to this service (the caller already ignored
/// requests for other services), in one pass down the layers: the request's
/// form (this layer), its values within the contract's limits, the hand
/// layer's rules for the command it becomes (all INVALID_ARGUMENT), the bus
/// and hand (UNKNOWN_HAND), administrative commands (the hand layer's rule,
/// DENIED unless `admin` allows them, saying why). Leases are the caller's
/// to check.
[[nodiscard]] Result<ValidRequest, Rejection> validate_request(const msg::CommandRequest& request,
                                                               const HandDirectory& directory,
                                                               AdminAccess admin);
/// The same, administrative commands allowed or off (`allow_admin`).
[[nodiscard]] Result<ValidRequest, Rejection> validate_request(const msg::CommandRequest& request,
                                                               const HandDirectory& directory,
                                                               bool allow_admin);

/// Why a command is refused to a client that does not hold `hand`'s lease:
/// who holds it and what was `refused`; `client_id_names_holder` when the
/// request's client_id field named the holder (a lease belongs to the
/// participant that took it, whatever a request says).
[[nodiscard]] std::string lease_refusal(const std::string& hand, const std::string& holder,
                                        const std::string& refused, bool client_id_names_holder);

}  // namespace dh3::dds
