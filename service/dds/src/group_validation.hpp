#pragma once
// All or none: a group request (msg::GroupRequest) is checked hand by hand
// before any of it reaches a bus. Each hand must pass what a single request
// to it would (form, range, known hand: validate_request()) and, because
// nothing of the group may move if one hand cannot, what the bus would only
// find out later: its bus is up, the hand online, initialized where the
// command needs it, and not leased by another client. Every failing hand is
// named with its code and why, not only the first.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "dh3/base/result.hpp"
#include "dh3/contract/dh3.h"
#include "hand_directory.hpp"
#include "request_validation.hpp"

namespace dh3::dds {

/// What the service knows of a hand at the moment of the check.
struct MemberFacts {
  bool link_up = false;
  bool online = false;
  bool initialized = false;
  /// Another client holding the hand's lease, as shown; nullopt if free or the caller's.
  std::optional<std::string> lease_blocker;
  /// The request's client_id field names that holder (another participant's claim).
  bool client_id_names_blocker = false;
};
using FactsOf = std::function<MemberFacts(std::uint16_t bus, std::uint8_t can_id)>;

struct MemberRefusal {
  std::size_t index = 0;  ///< in GroupRequest.hands
  Rejection why;
};

struct GroupRefusal {
  /// Empty when the request as a whole is malformed (then `whole` says why).
  std::vector<MemberRefusal> members;
  std::optional<Rejection> whole;
};

/// The group's commands are the ones that start or shape a motion.
[[nodiscard]] bool allowed_in_group(msg::CommandType command);

/// The hands' validated commands, in the request's order, or every refusal.
/// The request is addressed to this service (the caller checked).
[[nodiscard]] Result<std::vector<ValidRequest>, GroupRefusal> validate_group(
    const msg::GroupRequest& request, const HandDirectory& directory, const FactsOf& facts);

}  // namespace dh3::dds
