#pragma once
// The contract's filters read strings of a serialized sample in place.

#include <cstdint>
#include <string_view>

namespace dh3::contract {

/// Reads the CDR string at `offset` (aligned to 4 past the 4-byte
/// encapsulation) of a plain CDR payload, without copying, and moves `offset`
/// past it; false if the payload is not plain CDR or too short.
[[nodiscard]] bool read_serialized_string(const unsigned char* data, std::uint32_t length,
                                          std::uint32_t& offset, std::string_view& text);

}  // namespace dh3::contract
