#pragma once
// The secret that commands (and, by option, viewing) need: read once from a
// file, compared in constant time, never printed.

#include <string>
#include <string_view>

#include "dh3/base/result.hpp"

namespace dh3::web {

class BearerToken {
 public:
  /// The file's first line, surrounding white space removed. Refused: a
  /// missing or unreadable file; one that others may read or change, or
  /// its group (unless root owns it and gives its group reading only, as a
  /// packaged service's token is kept); an empty token, or one shorter than 16
  /// characters (a guessable secret is worse than none: it looks safe).
  static Result<BearerToken, std::string> from_file(const std::string& path);
  static BearerToken from_text(std::string token) { return BearerToken(std::move(token)); }

  /// True when `authorization` (the header's value) is "Bearer <this token>".
  [[nodiscard]] bool accepts(std::string_view authorization) const;

 private:
  explicit BearerToken(std::string token) : token_(std::move(token)) {}
  std::string token_;
};

}  // namespace dh3::web
