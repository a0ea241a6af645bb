#include "hand_api.hpp"

#include <charconv>
#include <vector>

#include "client_json.hpp"
#include "web_command.hpp"

namespace dh3::web {
namespace {

std::vector<std::string> split_path(const std::string& path) {
  std::vector<std::string> parts;
  std::size_t start = 1;  // after the leading '/'
  while (start <= path.size()) {
    const auto slash = path.find('/', start);
    const auto end = slash == std::string::npos ? path.size() : slash;
    parts.push_back(path.substr(start, end - start));
    start = end + 1;
  }
  return parts;
}

Result<HandAddress, ApiError> parse_address(const std::string& service, const std::string& bus,
                                            const std::string& id) {
  if (service.empty() || bus.empty()) {
    return fail(
        invalid_argument("a hand is /api/hands/SERVICE/BUS/ID; the service and the "
                         "bus must not be empty"));
  }
  unsigned value = 0;
  const auto* end = id.data() + id.size();
  const auto parsed = std::from_chars(id.data(), end, value);
  if (id.empty() || parsed.ec != std::errc() || parsed.ptr != end || value < 1 || value > 255) {
    return fail(invalid_argument("hand id '" + id + "' is not a CAN ID (1-255)"));
  }
  return HandAddress{service, bus, static_cast<std::uint16_t>(value)};
}

ApiResponse method_not_allowed(const ApiRequest& request, const std::string& allow) {
  ApiResponse response = error_response(ApiError{
      405, "METHOD_NOT_ALLOWED",
      request.method + " is not allowed on " + request.path + " (allowed: " + allow + ")"});
  response.allow = allow;
  return response;
}

ApiResponse json_response(std::string body) {
  ApiResponse response;
  response.body = std::move(body);
  return response;
}

}  // namespace

int http_status(Code code) {
  switch (code) {
    case Code::ok:
      return 200;
    case Code::invalid_argument:
      return 400;
    case Code::unknown_hand:
      return 404;
    case Code::denied:
      return 403;
    case Code::not_initialized:
    case Code::cancelled:
      return 409;
    case Code::failed:
      return 502;
    case Code::busy:
    case Code::bus_down:
    case Code::no_service:
    case Code::service_lost:
    case Code::not_connected:
      return 503;
    case Code::timeout:
    case Code::no_reply:
      return 504;
  }
  return 500;
}

ApiResponse error_response(const ApiError& error) {
  ApiResponse response;
  response.status = error.status;
  response.body = error.json();
  response.ask_for_token = error.status == 401;
  return response;
}

HandApi::HandApi(Client& client, AccessPolicy access, Timeout command_timeout, std::string openapi,
                 std::string console, CellAlarms* alarms)
    : client_(client),
      access_(std::move(access)),
      command_timeout_(command_timeout),
      openapi_(std::move(openapi)),
      console_(std::move(console)),
      alarms_(alarms) {}

std::optional<ApiResponse> HandApi::authorize_view(const std::string& authorization) const {
  if (!access_.view_needs_token || (access_.token && access_.token->accepts(authorization))) {
    return std::nullopt;
  }
  return error_response(ApiError{401, "UNAUTHORIZED",
                                 authorization.empty()
                                     ? "viewing needs the bearer token (Authorization: Bearer ...)"
                                     : "the bearer token is not the right one"});
}

std::optional<ApiResponse> HandApi::authorize_command(const std::string& authorization,
                                                      bool administrative) const {
  if (!access_.token) {
    return error_response(ApiError{403, "COMMANDS_DISABLED",
                                   "this dh3-web was started without --token-file: it shows the "
                                   "hands but takes no commands"});
  }
  const auto role = access_.token->role_of(authorization);
  if (!role) {
    return error_response(ApiError{
        401, "UNAUTHORIZED",
        authorization.empty() ? "commands need the bearer token (Authorization: Bearer ...)"
                              : "the bearer token is not the right one"});
  }
  if (*role == TokenRole::view) {
    return error_response(ApiError{403, "READ_ONLY_TOKEN",
                                   "this token may only view: commands need an operator's token"});
  }
  if (administrative && *role != TokenRole::administer) {
    return error_response(ApiError{403, "ADMIN_TOKEN_NEEDED",
                                   "administrative commands (set-can-id, set-baud) need an admin's "
                                   "token; this one is an operator's"});
  }
  return std::nullopt;
}

ApiResponse HandApi::handle(const ApiRequest& request) {
  const auto parts = split_path(request.path);  // {"api", ...}
  const bool get = request.method == "GET" || request.method == "HEAD";
  const std::size_t n = parts.size();
  // GET /api/stream is the server's own route; any other method ends here.
  if (n == 2 && parts[0] == "api" && parts[1] == "stream")
    return method_not_allowed(request, "GET");
  if (n == 2 && parts[1] == "openapi.json") {
    if (!get) return method_not_allowed(request, "GET");
    return json_response(openapi_);
  }
  if (n == 2 && parts[0] == "api" && parts[1] == "token") {
    if (!get) return method_not_allowed(request, "GET");
    return token_check(request.authorization);
  }
  if (n >= 2 && parts[0] == "api" && parts[1] == "alarms" && (n == 2 || n == 4)) {
    if (n == 2) {
      if (!get) return method_not_allowed(request, "GET");
      if (auto refused = authorize_view(request.authorization)) return *refused;
      return list_alarms();
    }
    if (parts[3] == "acknowledge") {
      if (request.method != "POST") return method_not_allowed(request, "POST");
      if (auto refused = authorize_command(request.authorization)) return *refused;
      return acknowledge_alarm(parts[2]);
    }
  }
  const bool known = n >= 2 && parts[0] == "api" &&
                     ((n == 2 && (parts[1] == "hands" || parts[1] == "health")) ||
                      (parts[1] == "hands" && (n == 5 || n == 6)));
  if (!known) {
    return error_response(
        ApiError{404, "NOT_FOUND",
                 "no such API path: " + request.path +
                     " (see /api/openapi.json: /api/hands, /api/hands/SERVICE/BUS/ID, "
                     "/api/hands/SERVICE/BUS/ID/COMMAND, /api/stream, /api/health, /api/token, "
                     "/api/alarms, /api/alarms/ID/acknowledge)"});
  }
  if (n == 6) {
    if (request.method != "POST") return method_not_allowed(request, "POST");
    if (auto refused = authorize_command(request.authorization)) return *refused;
    auto address = parse_address(parts[2], parts[3], parts[4]);
    if (!address) return error_response(address.error());
    return command(*address, parts[5], request.body, request.authorization);
  }
  if (!get) return method_not_allowed(request, "GET");
  if (auto refused = authorize_view(request.authorization)) return *refused;
  if (parts[1] == "health") return health();
  if (n == 2) return list_hands();
  auto address = parse_address(parts[2], parts[3], parts[4]);
  if (!address) return error_response(address.error());
  return one_hand(*address);
}

ApiResponse HandApi::list_hands() const {
  return json_response(
      json_text(Json{{"services", client_.services()}, {"hands", client_.hands()}}));
}

ApiResponse HandApi::one_hand(const HandAddress& address) const {
  const auto status = client_.status(address);
  if (!status) {
    return error_response(ApiError{404, "UNKNOWN_HAND",
                                   "no hand " + address.to_string() +
                                       " has been seen on the domain (GET /api/hands lists them)"});
  }
  return json_response(json_text(Json(*status)));
}

ApiResponse HandApi::command(const HandAddress& address, const std::string& name,
                             const std::string& body, const std::string& authorization) {
  auto parsed = parse_web_command(name, body);
  if (!parsed) return error_response(parsed.error());
  if (auto refused = authorize_command(authorization, is_administrative(parsed->name))) {
    return *refused;
  }
  // Only to hands this client has seen: a typo in the service's name would
  // otherwise wait for a service that never comes.
  if (!client_.status(address)) {
    return error_response(ApiError{404, "UNKNOWN_HAND",
                                   "no hand " + address.to_string() +
                                       " has been seen on the domain (GET /api/hands lists them)"});
  }
  Hand hand = client_.hand(address);
  const Reply reply = run_web_command(hand, *parsed, command_timeout_);
  ApiResponse response;
  response.status = http_status(reply.code);
  response.body = json_text(reply_json(parsed->name, address.to_string(), reply));
  if (reply.code != Code::ok && alarms_ != nullptr) {
    alarms_->record_failure(address.to_string(), parsed->name, response.status,
                            Json(reply.code).get<std::string>(), reply.message);
  }
  return response;
}

ApiResponse HandApi::list_alarms() const {
  if (alarms_ == nullptr) {
    return json_response(
        json_text(Json{{"type", "alarms"}, {"version", 0}, {"alarms", Json::array()}}));
  }
  return json_response(alarms_->alarms_json());
}

ApiResponse HandApi::acknowledge_alarm(const std::string& id) {
  std::uint64_t value = 0;
  const auto* end = id.data() + id.size();
  const auto parsed = std::from_chars(id.data(), end, value);
  std::optional<std::string> acknowledged;
  if (!id.empty() && parsed.ec == std::errc() && parsed.ptr == end && alarms_ != nullptr) {
    acknowledged = alarms_->acknowledge(value);
  }
  if (!acknowledged) {
    return error_response(ApiError{404, "UNKNOWN_ALARM",
                                   "no alarm " + id + " is listed (GET /api/alarms lists them; "
                                   "the oldest acknowledged ones leave a full list)"});
  }
  return json_response(std::move(*acknowledged));
}

ApiResponse HandApi::token_check(const std::string& authorization) const {
  // The page asks as soon as a token is typed: a wrong one is said at once,
  // not at the first command, and a right one with what it may do.
  if (!access_.token) return *authorize_command(authorization);
  const auto role = access_.token->role_of(authorization);
  if (!role) return *authorize_command(authorization);
  return json_response(json_text(Json{{"type", "token"},
                                      {"ok", true},
                                      {"role", std::string(role_name(*role))},
                                      {"console", console_}}));
}

ApiResponse HandApi::health() const {
  const CommandTraffic traffic = client_.command_traffic();
  std::size_t ready = 0;
  for (const auto& info : client_.services()) ready += info.ready ? 1 : 0;
  return json_response(json_text(
      Json{{"type", "health"},
           {"connected", client_.connected()},
           {"read_only", client_.read_only()},
           {"domain", client_.domain()},
           {"services_ready", ready},
           {"hands", client_.hands().size()},
           {"commands_enabled", access_.token && access_.token->grants(TokenRole::operate)},
           {"console", console_},
           {"requests_written", traffic.requests_written}}));
}

}  // namespace dh3::web
