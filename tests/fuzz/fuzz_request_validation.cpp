// libFuzzer target: a command request as the service receives it. The bytes
// are a serialized DDS sample (CDR encapsulation + body) and go through the
// same generated type support the service registers for its request topic
// (CommandRequestPubSubType), so the fuzzer reaches the wire type's
// deserialization as well as validate_request(). Whatever validates must be
// safe to queue: the hand layer accepts it, a written value is within the
// register's range, an administrative write only where allowed; whatever is
// refused says why with a code that fits.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "dh3/contract/dh3PubSubTypes.h"
#include "dh3/contract/type_support.hpp"
#include "dh3/hand/command_validation.hpp"
#include "dh3/protocol/registers.hpp"
#include "request_validation.hpp"

namespace {

using dh3::dds::RequestAction;

/// The service of the seeds: bus "box" with hands 1-3, bus "spare" with none.
const dh3::dds::HandDirectory& directory() {
  static const auto* const instance = [] {
    static const dh3::hand::HandRoster box({{1, "left"}, {2, ""}, {3, "right"}});
    static const dh3::hand::HandRoster spare;
    auto* d = new dh3::dds::HandDirectory;
    d->add_bus("box", box);
    d->add_bus("spare", spare);
    return d;
  }();
  return *instance;
}

bool is_admin(dh3::msg::CommandType command) {
  return command == dh3::msg::SET_CAN_ID || command == dh3::msg::SET_BAUD_RATE;
}

void check(bool holds) {
  if (!holds) std::abort();
}

void check_accepted(const dh3::msg::CommandRequest& request, const dh3::dds::ValidRequest& valid,
                    bool allow_admin) {
  namespace limits = dh3::limits;
  check(valid.bus < directory().bus_count());
  check(request.timeout_ms() <= limits::REQUEST_TIMEOUT_MAX_MS);
  check(!request.client_id().empty() && request.client_id().size() <= limits::MAX_NAME_LENGTH);
  switch (valid.action) {
    case RequestAction::scan:
      check(request.command() == dh3::msg::SCAN);
      return;
    case RequestAction::acquire_lease:
    case RequestAction::renew_lease: {
      const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(valid.lease_ttl);
      check(ms.count() >= limits::LEASE_TTL_MIN_MS && ms.count() <= limits::LEASE_TTL_MAX_MS);
      break;
    }
    case RequestAction::release_lease:
      break;
    case RequestAction::hand_command: {
      check(!is_admin(request.command()) || allow_admin);
      // What the DDS layer lets through, the hand layer queues.
      check(dh3::hand::validate(valid.can_id, valid.command, allow_admin).ok());
      if (valid.command.kind == dh3::hand::CommandKind::write_register) {
        check(dh3::protocol::check_write(valid.command.reg, valid.command.value).ok());
        check(allow_admin || !dh3::hand::is_admin_register(valid.command.reg));
      }
      break;
    }
  }
  // Every action but a scan addresses one known hand (or ID 0 for the CAN ID).
  check(valid.can_id == 0 || directory().has_hand(valid.bus, valid.can_id));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* bytes, std::size_t size) {
  // The sample as Fast DDS hands it to the type support: a copy of the bytes.
  eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<std::uint32_t>(size));
  std::copy(bytes, bytes + size, payload.data);
  payload.length = static_cast<std::uint32_t>(size);
  dh3::contract::TypeSupport<dh3::msg::CommandRequestPubSubType> type;
  dh3::msg::CommandRequest request;
  // Fast DDS's read/take may hand the sample on whatever deserialize() says,
  // so what it left in the struct is validated either way.
  type.deserialize(&payload, &request);

  bool accepted_without_admin = false;
  for (const bool allow_admin : {false, true}) {
    const auto verdict = dh3::dds::validate_request(request, directory(), allow_admin);
    if (verdict) {
      check_accepted(request, *verdict, allow_admin);
      accepted_without_admin = accepted_without_admin || !allow_admin;
      continue;
    }
    const auto& rejection = verdict.error();
    check(!rejection.message.empty());
    check(rejection.code == dh3::msg::INVALID_ARGUMENT ||
          rejection.code == dh3::msg::UNKNOWN_HAND ||
          (rejection.code == dh3::msg::DENIED && is_admin(request.command()) && !allow_admin));
    // Allowing administration never turns an accepted request into a refused one.
    check(!accepted_without_admin);
  }
  return 0;
}
