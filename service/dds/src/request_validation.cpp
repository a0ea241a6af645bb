#include "request_validation.hpp"

#include <chrono>
#include <optional>

#include "conversions.hpp"
#include "dh3/contract/value_ranges.hpp"
#include "dh3/hand/command_validation.hpp"
#include "dh3/protocol/registers.hpp"

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

/// The CAN ID and the value are within the contract's limits.
Checked check_request_ranges(const msg::CommandRequest& request) {
  const std::uint16_t can_id = request.hand().can_id();
  if (action_of(request.command()) != RequestAction::scan && can_id > limits::CAN_ID_MAX) {
    return reject(msg::INVALID_ARGUMENT,
                  "can_id " + std::to_string(can_id) + " is out of range (1-255)");
  }
  if (auto in_range = contract::check_value_range(request); !in_range) {
    return reject(msg::INVALID_ARGUMENT, std::move(in_range).error());
  }
  return {};
}

/// What the request becomes, before the bus is looked up.
ValidRequest translate(const msg::CommandRequest& request) {
  ValidRequest valid;
  valid.action = action_of(request.command());
  valid.can_id = static_cast<std::uint8_t>(request.hand().can_id());
  if (valid.action == RequestAction::hand_command) {
    valid.command = to_hand_command(request);
    valid.needs_lease = request.command() != msg::READ_REGISTER;
  } else if (valid.action == RequestAction::acquire_lease ||
             valid.action == RequestAction::renew_lease) {
    valid.lease_ttl = std::chrono::milliseconds(request.value());
  }
  return valid;
}

Rejection id_zero_rejection(msg::CommandType command) {
  return Rejection{msg::INVALID_ARGUMENT,
                   "can_id 0 addresses whichever hand is on the bus and is only for reading or "
                   "setting the CAN ID; " +
                       command_name(command) + " needs a hand's CAN ID (1-255)"};
}

/// The hand layer's rules (hand/command_validation.hpp), asked once of the
/// command the request becomes; nullopt if it passes. A scan is no command
/// for a hand, and a lease is held on one hand, never on ID 0.
std::optional<hand::ValidationFailure> hand_verdict(const ValidRequest& valid, bool allow_admin) {
  if (valid.action == RequestAction::scan) return std::nullopt;
  if (valid.action != RequestAction::hand_command) {
    if (valid.can_id != 0) return std::nullopt;
    hand::ValidationFailure lease_on_id_zero;
    lease_on_id_zero.rule = hand::CommandRule::id_zero;
    return lease_on_id_zero;
  }
  auto checked = hand::validate(valid.can_id, valid.command, allow_admin);
  if (checked) return std::nullopt;
  return std::move(checked).error();
}

/// The bus and the hand exist in this service; the bus's index.
Result<std::uint16_t, Rejection> check_request_target(const msg::CommandRequest& request,
                                                      const HandDirectory& directory) {
  const auto& address = request.hand();
  const std::uint16_t can_id = address.can_id();
  const auto bus = directory.find_bus(address.bus());
  if (!bus) {
    return reject(msg::UNKNOWN_HAND, "service '" + address.service() + "' has no bus '" +
                                         address.bus() + "' (its buses: " + directory.bus_names() +
                                         ")");
  }
  if (action_of(request.command()) != RequestAction::scan && can_id != 0 &&
      !directory.has_hand(*bus, static_cast<std::uint8_t>(can_id))) {
    return reject(msg::UNKNOWN_HAND, "no hand " + std::to_string(can_id) + " on bus '" +
                                         address.bus() + "' of service '" + address.service() +
                                         "'");
  }
  return *bus;
}

Rejection admin_rejection(const msg::CommandRequest& request, AdminAccess admin) {
  std::string text = command_name(request.command()) +
                     " is administrative (the hand must be rebooted after it) and service '" +
                     request.hand().service() + "' ";
  if (admin == AdminAccess::elsewhere) {
    text += std::string("takes it, under DDS Security, only on ") + dh3::topics::ADMIN_REQUEST +
            ", which only an admin identity may publish; it came on " +
            dh3::topics::COMMAND_REQUEST;
  } else {
    text += "does not allow it; start it with --allow-admin";
  }
  return Rejection{msg::DENIED, std::move(text)};
}

}  // namespace

Result<ValidRequest, Rejection> validate_request(const msg::CommandRequest& request,
                                                 const HandDirectory& directory, bool allow_admin) {
  return validate_request(request, directory,
                          allow_admin ? AdminAccess::allowed : AdminAccess::off);
}

Result<ValidRequest, Rejection> validate_request(const msg::CommandRequest& request,
                                                 const HandDirectory& directory,
                                                 AdminAccess admin) {
  // Down the layers once: this layer's fields, the contract's limits, the
  // hand layer's rules for the command, then the bus and the hand it names;
  // an administrative command is refused last, as DENIED, once all else holds.
  if (auto checked = check_request_fields(request); !checked) return fail(checked.error());
  if (auto checked = check_request_ranges(request); !checked) return fail(checked.error());
  ValidRequest valid = translate(request);
  const auto refused = hand_verdict(valid, admin == AdminAccess::allowed);
  if (refused && refused->rule == hand::CommandRule::id_zero) {
    return fail(id_zero_rejection(request.command()));
  }
  if (refused && refused->rule != hand::CommandRule::admin) {
    return reject(msg::INVALID_ARGUMENT, refused->message);
  }
  const auto bus = check_request_target(request, directory);
  if (!bus) return fail(bus.error());
  if (refused) return fail(admin_rejection(request, admin));
  valid.bus = *bus;
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
