#pragma once
// Between the wire types (dh3::msg, generated from idl/dh3.idl) and the client
// library's public types. Pure functions, so they are tested without DDS.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>

#include "dh3/base/result.hpp"
#include "dh3/contract/dh3.h"
#include "dh3/contract/names.hpp"
#include "dh3/types.hpp"

namespace dh3::detail {

[[nodiscard]] Code to_code(msg::ResultCode code);
[[nodiscard]] GraspOutcome to_public(msg::GraspOutcome outcome);
[[nodiscard]] GripState to_public(msg::GripState state);
[[nodiscard]] RotationState to_public(msg::RotationState state);
[[nodiscard]] EventKind to_public(msg::EventKind kind);

[[nodiscard]] HandAddress to_public(const msg::HandAddress& address);
[[nodiscard]] msg::HandAddress to_msg(const HandAddress& address);
[[nodiscard]] HandStatus to_public(const msg::HandStatus& status);
[[nodiscard]] HandEvent to_public(const msg::HandEvent& event);
[[nodiscard]] ServiceInfo to_public(const msg::ServiceInfo& info);
/// The reply as the caller sees it; a reply that is not OK but came without a
/// message gets one naming the code, so a user never sees an empty reason.
[[nodiscard]] Reply to_reply(const msg::CommandReply& reply);

using contract::command_name;

/// Checks a request against the contract's limits before it is sent, so an
/// out-of-range value is answered at once (the service checks again). The
/// message names the value, the allowed range and what it is: the refusal is
/// the reply the caller gets.
[[nodiscard]] Result<void, Reply> check_request(const msg::CommandRequest& request);

/// A reply the client makes itself (a local refusal, a deadline, a loss).
inline Reply make_reply(Code code, std::string message) {
  Reply reply;
  reply.code = code;
  reply.message = std::move(message);
  return reply;
}

/// "4.5 s", "200 ms": durations in messages.
[[nodiscard]] std::string describe_duration(std::chrono::milliseconds duration);

}  // namespace dh3::detail
