#pragma once
// A command as the HTTP API takes it: the command's name from the path (the
// names of dh3ctl's subcommands) and its values from a JSON body. Parsing
// checks names, fields and types; the value ranges are the client library's
// to check (it refuses them before anything is sent, in the service's words).

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "api_error.hpp"
#include "dh3/base/result.hpp"
#include "dh3/client.hpp"

namespace dh3::web {

struct WebCommand {
  std::string name;            ///< "move", "grasp", "acquire-lease", ...
  std::int32_t value = 0;      ///< the command's one number (position, force, ttl_ms, ...)
  std::optional<std::int32_t> opening;  ///< force: the optional opening force
  std::uint16_t register_code = 0;      ///< read
};

/// One field a command's body may carry.
struct CommandField {
  enum class Type : std::uint8_t { integer, text, boolean };
  std::string_view name;
  Type type = Type::integer;
  bool required = true;
};

/// A command the API knows, and the fields of its body.
struct CommandShape {
  std::string_view name;
  std::vector<CommandField> fields;
  /// Changes a setting stored in the hand: needs "confirm": true, as dh3ctl
  /// needs --yes.
  bool administrative = false;
};

/// Every command, in the order the page and the OpenAPI description list them.
[[nodiscard]] const std::vector<CommandShape>& command_shapes();
/// The command `name` is an administrative one (set-can-id, set-baud).
[[nodiscard]] bool is_administrative(std::string_view name);

/// `body` may be empty for commands without fields. Errors are 400
/// INVALID_ARGUMENT (malformed JSON, a missing, unknown or mistyped field) or
/// 404 UNKNOWN_COMMAND.
[[nodiscard]] Result<WebCommand, ApiError> parse_web_command(std::string_view name,
                                                             std::string_view body);

/// Sends `command` to `hand` and waits for its reply.
[[nodiscard]] Reply run_web_command(Hand& hand, const WebCommand& command, Timeout timeout);

}  // namespace dh3::web
