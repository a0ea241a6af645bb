#pragma once
// What a request brings (its path, a header) as it may stand in a log line:
// one line, nothing a terminal acts on. A path's "%0a" arrives decoded as a
// newline; written as it is, it would start a line of the sender's making.

#include <string>
#include <string_view>

namespace dh3::web {

/// `text` with every byte outside printable ASCII, and the backslash, written
/// as \xNN: "a\nb" -> "a\x0ab".
[[nodiscard]] std::string escaped_for_log(std::string_view text);

}  // namespace dh3::web
