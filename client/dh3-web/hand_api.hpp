#pragma once
// The JSON API without the HTTP server: a request (method, path, the
// Authorization header, body) in, a status and a JSON body out. Routing,
// the token check and every refusal happen here, before anything is sent, so
// tests drive all of it without a socket. The push stream (/api/stream) is
// the server's; it asks authorize_view() first.

#include <optional>
#include <string>

#include "api_error.hpp"
#include "bearer_token.hpp"
#include "cell_alarms.hpp"
#include "dh3/client.hpp"

namespace dh3::web {

struct AccessPolicy {
  /// Commands need an operator's or an admin's token of these, the
  /// administrative commands an admin's; without tokens they are refused
  /// (viewing only).
  std::optional<BearerToken> token;
  /// Reading statuses, events and the stream needs the token too.
  bool view_needs_token = false;
};

struct ApiRequest {
  std::string method;  ///< "GET", "POST", ...
  std::string path;    ///< decoded, without the query
  std::string authorization;
  std::string body;
};

struct ApiResponse {
  int status = 200;
  std::string body;
  /// 405: the methods the path takes (the Allow header).
  std::string allow;
  /// 401: ask for a bearer token (the WWW-Authenticate header).
  bool ask_for_token = false;
};

class HandApi {
 public:
  /// `openapi`: the description served at /api/openapi.json. `console`: how
  /// the services show this console's client as a lease holder. `alarms`: the
  /// console's alarm list (/api/alarms; a failed command is recorded there);
  /// without one /api/alarms is an empty list.
  HandApi(Client& client, AccessPolicy access, Timeout command_timeout, std::string openapi,
          std::string console = {}, CellAlarms* alarms = nullptr);

  [[nodiscard]] ApiResponse handle(const ApiRequest& request);
  /// Viewing allowed for this Authorization header; else the refusal.
  [[nodiscard]] std::optional<ApiResponse> authorize_view(const std::string& authorization) const;

 private:
  ApiResponse list_hands() const;
  ApiResponse one_hand(const HandAddress& address) const;
  ApiResponse command(const HandAddress& address, const std::string& name, const std::string& body,
                      const std::string& authorization);
  ApiResponse health() const;
  ApiResponse list_alarms() const;
  ApiResponse acknowledge_alarm(const std::string& id);
  ApiResponse token_check(const std::string& authorization) const;
  /// Commands allowed for this Authorization header (`administrative`: the
  /// administrative ones too); else the refusal.
  std::optional<ApiResponse> authorize_command(const std::string& authorization,
                                               bool administrative = false) const;

  Client& client_;
  AccessPolicy access_;
  Timeout command_timeout_;
  std::string openapi_;
  std::string console_;
  CellAlarms* alarms_;
};

/// The HTTP status for a command's reply: 200 for OK, else what the code means
/// (404 UNKNOWN_HAND, 409 NOT_INITIALIZED or a lease held elsewhere, 503 bus or
/// service away, 504 no answer in time, ...).
[[nodiscard]] int http_status(Code code);

[[nodiscard]] ApiResponse error_response(const ApiError& error);

}  // namespace dh3::web
