#include "bearer_token.hpp"

#include <openssl/crypto.h>

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

}  // namespace

Result<BearerToken, std::string> BearerToken::from_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) return fail("cannot read the token file " + path);
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
