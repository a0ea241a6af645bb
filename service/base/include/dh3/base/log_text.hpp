#pragma once
// Text from the network (a URL path, a header, a participant's announced
// name) as it may stand in a log line or be shown to people: one line, nothing
// a terminal acts on. A path's "%0a" arrives decoded as a newline; written as
// it is, it would start a line of the sender's making.

#include <string>
#include <string_view>

namespace dh3 {

/// `text` with every byte outside printable ASCII, and the backslash, written
/// as \xNN: "a\nb" -> "a\x0ab".
[[nodiscard]] std::string escaped_for_log(std::string_view text);

}  // namespace dh3
