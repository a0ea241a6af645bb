#pragma once
// The secrets that commands (and, by option, viewing) need: read once from a
// file, compared in constant time, never printed. Each token has a role:
// viewing only, driving hands, or also the administrative commands.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dh3/base/result.hpp"

namespace dh3::web {

/// What a token lets its holder do; each role may do what the ones before it may.
enum class TokenRole : std::uint8_t {
  view,       ///< read statuses, events and the stream (where viewing needs a token)
  operate,    ///< also command hands, except the administrative commands
  administer  ///< also SET_CAN_ID and SET_BAUD_RATE ("set-can-id", "set-baud")
};

/// "view", "operator", "admin": as the token file and the API name them.
[[nodiscard]] std::string_view role_name(TokenRole role);

class BearerToken {
 public:
  /// Either a file whose first line is one token (an operator's; the rest
  /// is not read), or one whose lines are "ROLE TOKEN", ROLE one of view,
  /// operator, admin (blank lines and lines starting with # skipped); a
  /// token given twice is refused. Refused too: a missing or unreadable
  /// file; one that others may read or change, or its group (unless root
  /// owns it and gives its group reading only, as a packaged service's
  /// token is kept); no token, or one shorter than 16 characters (a
  /// guessable secret is worse than none: it looks safe).
  static Result<BearerToken, std::string> from_file(const std::string& path);
  static BearerToken from_text(std::string token, TokenRole role = TokenRole::operate);

  /// The role of the token `authorization` (the header's value, "Bearer
  /// <token>") carries; nullopt if it carries none of these.
  [[nodiscard]] std::optional<TokenRole> role_of(std::string_view authorization) const;
  /// True when `authorization` carries one of these tokens, whatever its role.
  [[nodiscard]] bool accepts(std::string_view authorization) const {
    return role_of(authorization).has_value();
  }
  /// Some token has `role` or a greater one.
  [[nodiscard]] bool grants(TokenRole role) const;

 private:
  struct Entry {
    TokenRole role;
    std::string token;
  };
  explicit BearerToken(std::vector<Entry> tokens) : tokens_(std::move(tokens)) {}
  std::vector<Entry> tokens_;
};

}  // namespace dh3::web
