#include "bearer_token.hpp"

#include <openssl/crypto.h>
#include <sys/stat.h>

#include <cstdio>
#include <fstream>

namespace dh3::web {
namespace {

constexpr std::size_t kMinTokenLength = 16;

std::string_view trimmed(std::string_view text) {
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t\r\n");
  return text.substr(first, last - first + 1);
}

/// Why the file's owner and mode let someone else than dh3-web read or
/// change the token; empty if they do not.
std::string shared_token_file(const std::string& path, const struct stat& file) {
  const mode_t others = file.st_mode & (S_IRWXG | S_IRWXO);
  const bool root_group_reads = file.st_uid == 0 && others == S_IRGRP;
  if (others == 0 || root_group_reads) return {};
  char mode[8];
  std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(file.st_mode & 07777));
  return "the token file " + path + " has mode " + mode + ": " +
         ((file.st_mode & S_IRWXO) != 0 ? "other users" : "its group") +
         " may read or change the token; refused. chmod 600 " + path +
         " (or 640 owned by root with the group dh3-web runs as)";
}

}  // namespace

std::string_view role_name(TokenRole role) {
  switch (role) {
    case TokenRole::view:
      return "view";
    case TokenRole::operate:
      return "operator";
    case TokenRole::administer:
      return "admin";
  }
  return "view";
}

namespace {

std::optional<TokenRole> role_named(std::string_view name) {
  for (const TokenRole role : {TokenRole::view, TokenRole::operate, TokenRole::administer}) {
    if (name == role_name(role)) return role;
  }
  return std::nullopt;
}

/// Why `token` (on `where`) is no token; empty if it is one.
std::string weak_token(const std::string& token, const std::string& where) {
  if (token.size() >= kMinTokenLength) return {};
  return "the token " + where + " is " + (token.empty() ? "empty" : "too short") + " (at least " +
         std::to_string(kMinTokenLength) + " characters; e.g. head -c 24 /dev/urandom | base64)";
}

}  // namespace

Result<BearerToken, std::string> BearerToken::from_file(const std::string& path) {
  std::ifstream in(path);
  struct stat file {};
  if (!in || ::stat(path.c_str(), &file) != 0) return fail("cannot read the token file " + path);
  if (auto shared = shared_token_file(path, file); !shared.empty()) return fail(std::move(shared));
  std::vector<Entry> tokens;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const std::string_view text = trimmed(line);
    const std::string where = "on line " + std::to_string(number) + " of " + path;
    const auto space = text.find_first_of(" \t");
    if (number == 1 && space == std::string_view::npos && !text.starts_with('#')) {
      // A first line of one token: an operator's, as dh3-web always read it.
      if (auto weak = weak_token(std::string(text), "in " + path); !weak.empty()) {
        return fail(std::move(weak));
      }
      return BearerToken({{TokenRole::operate, std::string(text)}});
    }
    if (text.empty() || text.starts_with('#')) continue;
    const auto role = role_named(text.substr(0, space));
    if (space == std::string_view::npos || !role) {
      return fail("line " + std::to_string(number) + " of " + path +
                  " is not \"ROLE TOKEN\" with ROLE view, operator or admin");
    }
    std::string token(trimmed(text.substr(space)));
    if (auto weak = weak_token(token, where); !weak.empty()) return fail(std::move(weak));
    for (const Entry& known : tokens) {
      if (known.token == token) return fail("the token " + where + " is given twice");
    }
    tokens.push_back({*role, std::move(token)});
  }
  if (tokens.empty()) return fail(weak_token({}, "in " + path));
  return BearerToken(std::move(tokens));
}

BearerToken BearerToken::from_text(std::string token, TokenRole role) {
  return BearerToken({{role, std::move(token)}});
}

std::optional<TokenRole> BearerToken::role_of(std::string_view authorization) const {
  constexpr std::string_view kScheme = "Bearer ";
  if (authorization.substr(0, kScheme.size()) != kScheme) return std::nullopt;
  const std::string_view given = trimmed(authorization.substr(kScheme.size()));
  // CRYPTO_memcmp takes as long whatever the first difference, so the time
  // taken does not tell an attacker how much of a guess was right; every
  // token is compared, so neither does which one matched. The length is no
  // such hint: a token is at least kMinTokenLength random characters.
  std::optional<TokenRole> found;
  for (const Entry& entry : tokens_) {
    if (given.size() == entry.token.size() &&
        CRYPTO_memcmp(given.data(), entry.token.data(), entry.token.size()) == 0) {
      found = entry.role;
    }
  }
  return found;
}

bool BearerToken::grants(TokenRole role) const {
  for (const Entry& entry : tokens_) {
    if (entry.role >= role) return true;
  }
  return false;
}

}  // namespace dh3::web
