#pragma once
// Hexadecimal text read back into numbers: the candump log's CAN IDs and data,
// a participant's GUID prefix as the contract writes it (client_id_for).

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

namespace dh3 {

/// The value of one hex digit, either case; nullopt for any other character.
[[nodiscard]] std::optional<std::uint8_t> hex_digit(char c);

/// `hex`, two digits a byte, into `out`, which it must fill exactly; false
/// (and `out` partly written) for any other text.
[[nodiscard]] bool bytes_from_hex(std::string_view hex, std::span<std::uint8_t> out);

}  // namespace dh3
