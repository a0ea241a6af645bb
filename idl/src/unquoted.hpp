#pragma once
// The contract's filter factories read their parameters through this.

#include <string>
#include <string_view>

namespace dh3::contract {

/// DDSSQL spells a string parameter 'quoted'; accept that spelling too.
inline std::string unquoted(std::string_view text) {
  if (text.size() >= 2 && text.front() == '\'' && text.back() == '\'') {
    text = text.substr(1, text.size() - 2);
  }
  return std::string(text);
}

}  // namespace dh3::contract
