#pragma once
// The DH-3 registers a client may read by name, and how to show the firmware
// version. Mirrors the hand's register map (docs: the DH-3 protocol); the
// service checks every code again.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dh3/export.hpp"

namespace dh3 {

/// A register's 16-bit code: function << 8 | sub-function, e.g. 0x0602.
namespace reg {
inline constexpr std::uint16_t init_feedback = 0x0801;
inline constexpr std::uint16_t initialize = 0x0802;
inline constexpr std::uint16_t closing_force = 0x0502;
inline constexpr std::uint16_t opening_force = 0x0503;
inline constexpr std::uint16_t position = 0x0602;
inline constexpr std::uint16_t rotation = 0x0702;
inline constexpr std::uint16_t grip_status = 0x0F01;
inline constexpr std::uint16_t rotation_status = 0x0F02;
inline constexpr std::uint16_t can_id = 0x1201;
inline constexpr std::uint16_t firmware_version = 0x1301;
inline constexpr std::uint16_t baud_rate = 0x1401;
}  // namespace reg

struct RegisterName {
  std::uint16_t code = 0;
  std::string_view name;  ///< e.g. "position"
};

/// Every register of the map with its name.
[[nodiscard]] DH3_CLIENT_API const std::vector<RegisterName>& registers();
/// "position" for 0x0602; empty for codes outside the map.
[[nodiscard]] DH3_CLIENT_API std::string_view register_name(std::uint16_t code);
/// A register by name ("position", "grip-status" or "grip_status") or by code
/// ("0x0602", "0602" is not accepted: hex needs 0x; "1538" is decimal).
[[nodiscard]] DH3_CLIENT_API std::optional<std::uint16_t> parse_register(std::string_view text);
/// Firmware version 0x1301 as the hand reports it: its bytes from high to low
/// joined by dots; raw 0x04010200 reads "4.1.2.0".
[[nodiscard]] DH3_CLIENT_API std::string firmware_version_text(std::int32_t raw);

}  // namespace dh3
