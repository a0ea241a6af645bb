#pragma once
// The JSON of the client library's public types, one spelling for every
// program that prints them (dh3ctl --json, dh3-web's API and event stream) and
// for the check of dh3-web's openapi.json: nlohmann's to_json, found by ADL,
// so `Json(status)` and `Json(services)` work. Objects keep their members in
// the order written here (ordered_json).
//
// Shapes: a HandAddress is its text "service/bus/id"; the enums are the
// strings to_string() gives; a status, event or service object starts with its
// "type". Fields that matter for some commands only (a reply's grasp,
// found_ids and lease_holder) are left out when they are empty.

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "dh3/client.hpp"
#include "dh3/group.hpp"
#include "dh3/types.hpp"

namespace dh3 {

using Json = nlohmann::ordered_json;

void to_json(Json& json, Code code);
void to_json(Json& json, GraspOutcome outcome);
void to_json(Json& json, GripState state);
void to_json(Json& json, RotationState state);
void to_json(Json& json, EventKind kind);
void to_json(Json& json, GroupCommand command);
void to_json(Json& json, const HandAddress& address);
void to_json(Json& json, const HandStatus& status);
void to_json(Json& json, const HandEvent& event);
void to_json(Json& json, const HandInfo& hand);
void to_json(Json& json, const BusInfo& bus);
void to_json(Json& json, const ServiceInfo& info);
/// ok, code, message, value, and what `reply` carries of grasp, found_ids and lease_holder.
void to_json(Json& json, const Reply& reply);
void to_json(Json& json, const GroupMemberReply& member);
void to_json(Json& json, const GroupReply& reply);
void to_json(Json& json, const CommandTraffic& traffic);
void to_json(Json& json, const WatchTraffic& traffic);

/// {"type":"reply","command":..,"hand":..,} and the reply's fields; a scan's
/// found_ids even when none answered.
[[nodiscard]] Json reply_json(std::string_view command, std::string_view target,
                              const Reply& reply);

/// `json` on one line. Text that is not UTF-8 (a name from the wire) is
/// printed with U+FFFD in place of the bad bytes rather than refused.
[[nodiscard]] std::string json_text(const Json& json);

}  // namespace dh3
