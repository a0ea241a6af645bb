// The client's public types as JSON (client_json.hpp).

#include "client_json.hpp"

#include "dh3/registers.hpp"

namespace dh3 {
namespace {

/// A value the hand has not reported yet is null, not the -1 that holds its place.
Json read_or_null(std::int32_t value) {
  return value < 0 ? Json(nullptr) : Json(value);
}

Json known_or_null(std::optional<std::int32_t> value) {
  return value ? Json(*value) : Json(nullptr);
}

}  // namespace

void to_json(Json& json, Code code) {
  json = to_string(code);
}
void to_json(Json& json, GraspOutcome outcome) {
  json = to_string(outcome);
}
void to_json(Json& json, GripState state) {
  json = to_string(state);
}
void to_json(Json& json, RotationState state) {
  json = to_string(state);
}
void to_json(Json& json, EventKind kind) {
  json = to_string(kind);
}
void to_json(Json& json, GroupCommand command) {
  json = to_string(command);
}

void to_json(Json& json, const HandAddress& address) {
  json = address.to_string();
}

void to_json(Json& json, const HandStatus& s) {
  json = Json{{"type", "status"},
              {"hand", s.address},
              {"service", s.address.service},
              {"bus", s.address.bus},
              {"can_id", s.address.can_id},
              {"name", s.name},
              {"online", s.online},
              {"initialized", s.initialized},
              {"grip", s.grip},
              {"position", read_or_null(s.position)},
              {"target_position", read_or_null(s.target_position)},
              {"closing_force", read_or_null(s.closing_force)},
              {"opening_force", read_or_null(s.opening_force)},
              {"rotation", read_or_null(s.rotation)},
              {"rotation_target", read_or_null(s.rotation_target)},
              {"rotation_state", s.rotation_state},
              {"firmware_version", s.firmware_version},
              {"firmware_version_text", s.firmware_version_text},
              {"last_error", s.last_error},
              {"last_error_message", s.last_error_message},
              {"lease_holder", s.lease_holder},
              {"timestamp_ns", s.timestamp_ns},
              {"update_seq", s.update_seq},
              {"read_at_ns", s.read_at_ns},
              {"service_lost", s.service_lost}};
}

void to_json(Json& json, const HandEvent& e) {
  json = Json{{"type", "event"},
              {"hand", e.hand},
              {"name", e.name},
              {"kind", e.kind},
              {"position", known_or_null(e.position)},
              {"target", e.target},
              {"value", e.value},
              {"message", e.message},
              {"timestamp_ns", e.timestamp_ns},
              {"event_seq", e.event_seq},
              {"from_client", e.from_client}};
  // What the value means, under its name, beside it.
  if (const auto named = named_value(e)) {
    json[std::string(named->name)] = named->value;
    if (e.kind == EventKind::online) json["firmware_version_text"] = firmware_version_text(e.value);
  }
}

void to_json(Json& json, const HandInfo& hand) {
  json = Json{{"can_id", hand.can_id}, {"name", hand.name}};
}

void to_json(Json& json, const BusInfo& bus) {
  json =
      Json{{"name", bus.name}, {"spec", bus.spec}, {"link_up", bus.link_up}, {"hands", bus.hands}};
}

void to_json(Json& json, const ServiceInfo& info) {
  json = Json{{"type", "service"},
              {"service", info.name},
              {"version", info.version},
              {"host", info.host},
              {"admin_allowed", info.admin_allowed},
              {"ready", info.ready},
              {"started_ns", info.started_ns},
              {"buses", info.buses}};
}

void to_json(Json& json, const Reply& reply) {
  json = Json{
      {"ok", reply.ok()}, {"code", reply.code}, {"message", reply.message}, {"value", reply.value}};
  if (reply.grasp != GraspOutcome::none) json["grasp"] = reply.grasp;
  if (!reply.found_ids.empty()) json["found_ids"] = reply.found_ids;
  if (!reply.lease_holder.empty()) json["lease_holder"] = reply.lease_holder;
}

void to_json(Json& json, const GroupMemberReply& member) {
  json = Json{{"hand", member.hand},
              {"ok", member.ok()},
              {"code", member.code},
              {"message", member.message},
              {"value", member.value}};
  if (member.grasp != GraspOutcome::none) json["grasp"] = member.grasp;
}

void to_json(Json& json, const GroupReply& reply) {
  json = Json{
      {"ok", reply.ok()}, {"code", reply.code}, {"message", reply.message}, {"hands", reply.hands}};
}

void to_json(Json& json, const CommandTraffic& traffic) {
  json = Json{{"requests_written", traffic.requests_written},
              {"own_replies", traffic.own_replies},
              {"foreign_replies", traffic.foreign_replies}};
}

void to_json(Json& json, const WatchTraffic& traffic) {
  json = Json{{"statuses", traffic.statuses},
              {"events", traffic.events},
              {"infos", traffic.infos},
              {"dropped_on_arrival", traffic.dropped_on_arrival}};
}

Json reply_json(std::string_view command, std::string_view target, const Reply& reply) {
  Json json{{"type", "reply"}, {"command", command}, {"hand", target}};
  json.update(Json(reply));
  if (command == "scan" && !json.contains("found_ids")) json["found_ids"] = Json::array();
  // What the text output says besides the value: where a grasp stopped, and
  // the firmware version as its string.
  if (reply.ok() && command == "grasp") json["position"] = reply.value;
  if (reply.ok() && command == "version") {
    json["firmware_version_text"] = firmware_version_text(reply.value);
  }
  return json;
}

std::string json_text(const Json& json) {
  return json.dump(-1, ' ', false, Json::error_handler_t::replace);
}

}  // namespace dh3
