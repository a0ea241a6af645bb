#include "request_validation.hpp"

#include <chrono>
#include <cstdio>
#include <optional>

#include "conversions.hpp"
#include "dh3/hand/command_validation.hpp"
#include "dh3/protocol/registers.hpp"
#include "dh3_value_ranges.hpp"

namespace dh3::dds {
namespace {

using hand::CommandKind;

Failure<Rejection> reject(msg::ResultCode code, std::string message) {
  return fail(Rejection{code, std::move(message)});
}

hand::Command to_hand_command(const msg::CommandRequest& request) {
  hand::Command command;
  command.value = request.value();
  switch (request.command()) {
    case msg::INITIALIZE:
      command.kind = CommandKind::initialize;
      break;
    case msg::MOVE:
      command.kind = CommandKind::move_to;
      break;
    case msg::SET_CLOSING_FORCE:
      command.kind = CommandKind::set_closing_force;
      break;
    case msg::SET_OPENING_FORCE:
      command.kind = CommandKind::set_opening_force;
      break;
    case msg::ROTATE:
      command.kind = CommandKind::rotate_to;
      break;
    case msg::READ_REGISTER:
      command.kind = CommandKind::read_register;
      command.reg = protocol::Register::from_code(request.register_code());
      command.value = 0;
      break;
    case msg::SET_CAN_ID:
      command.kind = CommandKind::write_register;
      command.reg = protocol::reg::kCanId;
      break;
    case msg::SET_BAUD_RATE:
      command.kind = CommandKind::write_register;
      command.reg = protocol::reg::kBaudRate;
      break;
    case msg::ENABLE_INIT_FEEDBACK:
      // The document enables it by writing 0 (the hand answers 0xA5).
      command.kind = CommandKind::write_register;
      command.reg = protocol::reg::kInitFeedback;
      command.value = 0;
      break;
    case msg::GRASP:
      command.kind = CommandKind::grasp;
      break;
    case msg::RELEASE:
      command.kind = CommandKind::release;
      break;
    case msg::STOP:
      command.kind = CommandKind::stop;
      command.value = 0;
      break;
    default:
      break;  // not a hand command; never called for those
  }
  if (request.timeout_ms() != 0) {
    command.timeout = std::chrono::milliseconds(request.timeout_ms());
  }
  return command;
}

// The admin and ID-0 rules are the hand layer's (hand/command_validation.hpp),
// asked of the command the request becomes; requests that are not hand
// commands (scan, leases) are neither.
bool is_admin(const msg::CommandRequest& request) {
  return hand::is_admin_command(to_hand_command(request));
}

bool allows_id_zero(const msg::CommandRequest& request) {
  return hand::may_address_id_zero(to_hand_command(request));
}

RequestAction action_of(msg::CommandType command) {
  switch (command) {
    case msg::SCAN:
      return RequestAction::scan;
    case msg::ACQUIRE_LEASE:
      return RequestAction::acquire_lease;
    case msg::RENEW_LEASE:
      return RequestAction::renew_lease;
    case msg::RELEASE_LEASE:
      return RequestAction::release_lease;
    default:
      return RequestAction::hand_command;
  }
}

}  // namespace

namespace {

using Checked = Result<void, Rejection>;

/// What every request must carry: a client, a service, a known command, a bus,
/// a timeout within the limit.
Checked check_request_fields(const msg::CommandRequest& request) {
  const auto& client = request.client_id();
  if (client.empty()) return reject(msg::INVALID_ARGUMENT, "client_id is empty");
  if (client.size() > limits::MAX_NAME_LENGTH) {
    return reject(
        msg::INVALID_ARGUMENT,
        "client_id is longer than " + std::to_string(limits::MAX_NAME_LENGTH) + " characters");
  }
  const auto& address = request.hand();
  if (address.service().empty()) {
    return reject(msg::INVALID_ARGUMENT, "hand.service is empty; name the service to command");
  }
  const msg::CommandType command = request.command();
  if (!is_valid_command(command)) {
    return reject(msg::INVALID_ARGUMENT,
                  "unknown command " + std::to_string(static_cast<std::uint32_t>(command)));
  }
  if (address.bus().empty()) return reject(msg::INVALID_ARGUMENT, "hand.bus is empty");
  if (request.timeout_ms() > limits::REQUEST_TIMEOUT_MAX_MS) {
    return reject(msg::INVALID_ARGUMENT, "timeout_ms " + std::to_string(request.timeout_ms()) +
                                             " is over the maximum of " +
                                             std::to_string(limits::REQUEST_TIMEOUT_MAX_MS));
  }
  return {};
}

/// The CAN ID, the value and the register are within the contract's limits.
Checked check_request_values(const msg::CommandRequest& request) {
  const msg::CommandType command = request.command();
  const std::uint16_t can_id = request.hand().can_id();
  const RequestAction action = action_of(command);
  if (action != RequestAction::scan) {
    if (can_id > limits::CAN_ID_MAX) {
      return reject(msg::INVALID_ARGUMENT,
                    "can_id " + std::to_string(can_id) + " is out of range (1-255)");
    }
    if (can_id == 0 && !allows_id_zero(request)) {
      return reject(msg::INVALID_ARGUMENT,
                    "can_id 0 addresses whichever hand is on the bus and is only for reading "
                    "or setting the CAN ID; " +
                        command_name(command) + " needs a hand's CAN ID (1-255)");
    }
  }
  if (auto in_range = contract::check_value_range(request); !in_range) {
    return reject(msg::INVALID_ARGUMENT, std::move(in_range).error());
  }
  if (command == msg::READ_REGISTER &&
      !protocol::is_known(protocol::Register::from_code(request.register_code()))) {
    char code[8];
    std::snprintf(code, sizeof code, "0x%04X", static_cast<unsigned>(request.register_code()));
    return reject(msg::INVALID_ARGUMENT,
                  std::string("register ") + code + " is not in the DH-3 register map");
  }
  return {};
}

/// The bus and the hand exist in this service, and an administrative command
/// is allowed; the bus's index.
Result<std::uint16_t, Rejection> check_request_target(const msg::CommandRequest& request,
                                                      const HandDirectory& directory,
                                                      bool allow_admin) {
  const auto& address = request.hand();
  const msg::CommandType command = request.command();
  const std::uint16_t can_id = address.can_id();
  const auto bus = directory.find_bus(address.bus());
  if (!bus) {
    return reject(msg::UNKNOWN_HAND, "service '" + address.service() + "' has no bus '" +
                                         address.bus() + "' (its buses: " + directory.bus_names() +
                                         ")");
  }
  if (action_of(command) != RequestAction::scan && can_id != 0 &&
      !directory.has_hand(*bus, static_cast<std::uint8_t>(can_id))) {
    return reject(msg::UNKNOWN_HAND, "no hand " + std::to_string(can_id) + " on bus '" +
                                         address.bus() + "' of service '" + address.service() +
                                         "'");
  }
  if (is_admin(request) && !allow_admin) {
    return reject(msg::DENIED, command_name(command) +
                                   " is administrative (the hand must be rebooted after it) and "
                                   "service '" +
                                   address.service() +
                                   "' does not allow it; start it with --allow-admin");
  }
  return *bus;
}

}  // namespace

Result<ValidRequest, Rejection> validate_request(const msg::CommandRequest& request,
                                                 const HandDirectory& directory, bool allow_admin) {
  if (auto checked = check_request_fields(request); !checked) return fail(checked.error());
  if (auto checked = check_request_values(request); !checked) return fail(checked.error());
  const auto bus = check_request_target(request, directory, allow_admin);
  if (!bus) return fail(bus.error());
  const msg::CommandType command = request.command();
  const RequestAction action = action_of(command);
  const std::uint16_t can_id = request.hand().can_id();
  ValidRequest valid;
  valid.action = action;
  valid.bus = *bus;
  valid.can_id = static_cast<std::uint8_t>(can_id);
  if (action == RequestAction::hand_command) {
    valid.command = to_hand_command(request);
    valid.needs_lease = command != msg::READ_REGISTER;
  } else if (action == RequestAction::acquire_lease || action == RequestAction::renew_lease) {
    valid.lease_ttl = std::chrono::milliseconds(request.value());
  }
  return valid;
}

std::string lease_refusal(const std::string& hand, const std::string& holder,
                          const std::string& refused, bool client_id_names_holder) {
  std::string text = hand + " is leased by client '" + holder + "'; " + refused;
  if (client_id_names_holder) {
    text +=
        ": the request's client_id names the holder, but the request came from another "
        "participant, and a lease belongs to the participant that took it";
  }
  return text;
}

}  // namespace dh3::dds
