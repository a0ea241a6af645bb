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

Result<BearerToken, std::string> BearerToken::from_file(const std::string& path) {
  std::ifstream in(path);
  struct stat file {};
  if (!in || ::stat(path.c_str(), &file) != 0) return fail("cannot read the token file " + path);
  if (auto shared = shared_token_file(path, file); !shared.empty()) return fail(std::move(shared));
  std::string line;
  std::getline(in, line);
  const std::string token(trimmed(line));
  if (token.size() < kMinTokenLength) {
    return fail("the token in " + path + " is " + (token.empty() ? "empty" : "too short") +
                " (at least " + std::to_string(kMinTokenLength) +
                " characters; e.g. head -c 24 /dev/urandom | base64 > FILE)");
  }
  return BearerToken(token);
}

bool BearerToken::accepts(std::string_view authorization) const {
  constexpr std::string_view kScheme = "Bearer ";
  if (authorization.substr(0, kScheme.size()) != kScheme) return false;
  const std::string_view given = trimmed(authorization.substr(kScheme.size()));
  // CRYPTO_memcmp takes as long whatever the first difference, so the time
  // taken does not tell an attacker how much of a guess was right. The
  // length is no such hint: a token is at least kMinTokenLength random characters.
  return given.size() == token_.size() &&
         CRYPTO_memcmp(given.data(), token_.data(), token_.size()) == 0;
}

}  // namespace dh3::web
