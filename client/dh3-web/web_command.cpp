#include "web_command.hpp"

#include <limits>

#include <nlohmann/json.hpp>

#include "dh3/registers.hpp"

namespace dh3::web {
namespace {

using Type = CommandField::Type;
using Json = nlohmann::json;

std::string_view type_name(Type type) {
  switch (type) {
    case Type::integer:
      return "an integer";
    case Type::text:
      return "a string";
    case Type::boolean:
      return "true or false";
  }
  return "?";
}

bool has_type(const Json& value, Type type) {
  switch (type) {
    case Type::integer:
      return value.is_number_integer();
    case Type::text:
      return value.is_string();
    case Type::boolean:
      return value.is_boolean();
  }
  return false;
}

std::string field_list(const CommandShape& shape) {
  if (shape.fields.empty()) return "none";
  std::string names;
  for (const auto& field : shape.fields) {
    if (!names.empty()) names += ", ";
    names += field.name;
    if (!field.required) names += " (optional)";
  }
  return names;
}

const CommandShape* find_shape(std::string_view name) {
  for (const auto& shape : command_shapes()) {
    if (shape.name == name) return &shape;
  }
  return nullptr;
}

/// The body as a JSON object; empty text is {}.
Result<Json, ApiError> parse_body(std::string_view body) {
  if (body.find_first_not_of(" \t\r\n") == std::string_view::npos) return Json::object();
  Json parsed = Json::parse(body, nullptr, /*allow_exceptions=*/false);
  if (parsed.is_discarded()) {
    // nlohmann's exception carries the position; its non-throwing parse does
    // not, so parse again for the message (bad input only, never the data path).
    std::string why = "not JSON";
    try {
      const Json again = Json::parse(body);
    } catch (const Json::parse_error& error) {
      why = error.what();
    }
    return fail(invalid_argument("the body is malformed JSON: " + why));
  }
  if (!parsed.is_object()) {
    return fail(invalid_argument(std::string("the body must be a JSON object, not ") +
                                 parsed.type_name()));
  }
  return parsed;
}

/// Every field of `body` is one of the shape's, of the right type; every
/// required one is there.
Result<void, ApiError> check_fields(const CommandShape& shape, const Json& body) {
  for (const auto& [key, value] : body.items()) {
    const CommandField* field = nullptr;
    for (const auto& candidate : shape.fields) {
      if (candidate.name == key) field = &candidate;
    }
    if (field == nullptr) {
      return fail(invalid_argument("unknown field '" + key + "' for " + std::string(shape.name) +
                                   " (its fields: " + field_list(shape) + ")"));
    }
    if (!has_type(value, field->type)) {
      return fail(invalid_argument("field '" + key + "' of " + std::string(shape.name) +
                                   " must be " + std::string(type_name(field->type)) + ", not " +
                                   value.dump()));
    }
    if (field->type == Type::integer &&
        (value.is_number_unsigned()
             ? value.get<std::uint64_t>() >
                   static_cast<std::uint64_t>(std::numeric_limits<std::int32_t>::max())
             : (value.get<std::int64_t>() < std::numeric_limits<std::int32_t>::min() ||
                value.get<std::int64_t>() > std::numeric_limits<std::int32_t>::max()))) {
      return fail(invalid_argument("field '" + key + "' of " + std::string(shape.name) + " (" +
                                   value.dump() + ") is out of range"));
    }
  }
  for (const auto& field : shape.fields) {
    if (field.required && !body.contains(field.name)) {
      return fail(invalid_argument(std::string(shape.name) + " needs the field '" +
                                   std::string(field.name) + "' (its fields: " +
                                   field_list(shape) + ")"));
    }
  }
  return {};
}

}  // namespace

bool is_administrative(std::string_view name) {
  const CommandShape* shape = find_shape(name);
  return shape != nullptr && shape->administrative;
}

const std::vector<CommandShape>& command_shapes() {
  static const std::vector<CommandShape> shapes = {
      {"init", {}},
      {"move", {{"position"}}},
      {"rotate", {{"rotation"}}},
      {"force", {{"closing"}, {"opening", Type::integer, false}}},
      {"grasp", {{"force"}}},
      {"release", {{"position"}}},
      {"stop", {}},
      {"read", {{"register", Type::text}}},
      {"version", {}},
      {"scan", {}},
      {"acquire-lease", {{"ttl_ms"}}},
      {"renew-lease", {{"ttl_ms"}}},
      {"release-lease", {}},
      {"set-can-id", {{"can_id"}, {"confirm", Type::boolean}}, true},
      {"set-baud", {{"index"}, {"confirm", Type::boolean}}, true},
  };
  return shapes;
}

Result<WebCommand, ApiError> parse_web_command(std::string_view name, std::string_view body) {
  const CommandShape* shape = find_shape(name);
  if (shape == nullptr) {
    std::string names;
    for (const auto& known : command_shapes()) {
      if (!names.empty()) names += ", ";
      names += known.name;
    }
    return fail(ApiError{404, "UNKNOWN_COMMAND",
                         "no command '" + std::string(name) + "' (commands: " + names + ")"});
  }
  auto parsed = parse_body(body);
  if (!parsed) return fail(std::move(parsed).error());
  const Json& json = *parsed;
  if (auto checked = check_fields(*shape, json); !checked) return fail(std::move(checked).error());

  WebCommand command;
  command.name = std::string(shape->name);
  for (const auto& field : shape->fields) {
    if (!json.contains(field.name)) continue;
    const Json& value = json.at(std::string(field.name));
    if (field.name == "opening") {
      command.opening = value.get<std::int32_t>();
    } else if (field.name == "confirm") {
      if (!value.get<bool>()) {
        return fail(invalid_argument(
            std::string(shape->name) +
            " changes a setting stored in the hand, which must then be rebooted; send "
            "\"confirm\": true"));
      }
    } else if (field.type == Type::text) {
      const auto text = value.get<std::string>();
      const auto code = parse_register(text);
      if (!code) {
        return fail(invalid_argument("unknown register '" + text +
                                     "' (a name such as position, or 0xNNNN)"));
      }
      command.register_code = *code;
    } else {
      command.value = value.get<std::int32_t>();
    }
  }
  return command;
}

Reply run_web_command(Hand& hand, const WebCommand& c, Timeout timeout) {
  const std::string& n = c.name;
  if (n == "init") return hand.initialize(timeout);
  if (n == "move") return hand.move_to(c.value, timeout);
  if (n == "rotate") return hand.rotate_to(c.value, timeout);
  if (n == "force") return hand.set_force(c.value, c.opening, timeout);
  if (n == "grasp") return hand.grasp(c.value, timeout);
  if (n == "release") return hand.release(c.value, timeout);
  if (n == "stop") return hand.stop(timeout);
  if (n == "read") return hand.read(c.register_code, timeout);
  if (n == "version") return hand.read(reg::firmware_version, timeout);
  if (n == "scan") return hand.scan_bus(timeout);
  if (n == "acquire-lease") return hand.acquire_lease(std::chrono::milliseconds(c.value), timeout);
  if (n == "renew-lease") return hand.renew_lease(std::chrono::milliseconds(c.value), timeout);
  if (n == "release-lease") return hand.release_lease(timeout);
  if (n == "set-can-id") return hand.set_can_id(c.value, timeout);
  if (n == "set-baud") return hand.set_baud_rate(c.value, timeout);
  Reply reply;
  reply.code = Code::invalid_argument;
  reply.message = "unknown command '" + n + "'";
  return reply;
}

}  // namespace dh3::web
