#pragma once
// What dh3-web answers when it refuses a request itself: an HTTP status and a
// JSON body in the shape of dh3ctl --json's failed replies, so a script reads
// "ok", "code" and "message" the same way whoever said no.

#include <string>

namespace dh3::web {

struct ApiError {
  int status = 400;
  /// "INVALID_ARGUMENT", "UNKNOWN_HAND", "UNAUTHORIZED", "METHOD_NOT_ALLOWED", ...
  std::string code;
  std::string message;

  /// {"type":"error","ok":false,"code":"...","message":"..."}
  [[nodiscard]] std::string json() const;
};

[[nodiscard]] inline ApiError invalid_argument(std::string message) {
  return ApiError{400, "INVALID_ARGUMENT", std::move(message)};
}

}  // namespace dh3::web
