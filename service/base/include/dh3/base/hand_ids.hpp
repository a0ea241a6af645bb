#pragma once
// A list of hand IDs as every command line and bus spec of dh3 reads it:
// "1,2,3" or "1-8,10". A hand's ID is its CAN ID, 1-255 (ID 0 addresses
// whichever hand is there, so it names none).

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "dh3/base/result.hpp"

namespace dh3 {

/// One hand ID, 1-255; the error says why not ("hand id 0 is not a hand's id ...").
[[nodiscard]] Result<std::uint8_t, std::string> parse_hand_id(std::string_view text);

/// The IDs in the order given, each once; the error names the item that is
/// wrong ("hand id 'x' is not a number", "hand id 256 is out of range
/// 1-255", "hand id 3 is listed twice", "empty range 8-1").
[[nodiscard]] Result<std::vector<std::uint8_t>, std::string> parse_hand_ids(std::string_view text);

}  // namespace dh3
