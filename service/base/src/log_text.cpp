#include "dh3/base/log_text.hpp"

#include <cstdio>

namespace dh3 {

std::string escaped_for_log(std::string_view text) {
  std::string escaped;
  escaped.reserve(text.size());
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte >= 0x20 && byte < 0x7f && byte != '\\') {
      escaped.push_back(c);
      continue;
    }
    char code[5];
    std::snprintf(code, sizeof code, "\\x%02x", static_cast<unsigned>(byte));
    escaped += code;
  }
  return escaped;
}

}  // namespace dh3
