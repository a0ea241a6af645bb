#pragma once
// The DH-3 register map (spec: "Command overview") and the value range the
// document allows for each writable register. Out-of-range values are rejected,
// never clamped (docs/protocol-notes.md reading 12).

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "dh3/base/result.hpp"

namespace dh3::protocol {

/// A register is a (function, sub-function) pair; `code()` is the 16-bit form
/// the document and docs/protocol-notes.md use, e.g. 0x0602 for position.
struct Register {
  std::uint8_t function = 0;
  std::uint8_t sub_function = 0;

  [[nodiscard]] constexpr std::uint16_t code() const {
    return static_cast<std::uint16_t>((function << 8) | sub_function);
  }
  static constexpr Register from_code(std::uint16_t code) {
    return Register{static_cast<std::uint8_t>(code >> 8), static_cast<std::uint8_t>(code & 0xFF)};
  }
  friend constexpr bool operator==(Register, Register) = default;
};

namespace reg {
inline constexpr Register kInitFeedback{0x08, 0x01};    ///< feedback after initialization
inline constexpr Register kInitialize{0x08, 0x02};      ///< write: initialize; read: finished?
inline constexpr Register kClosingForce{0x05, 0x02};    ///< gripping force, 20-100 %
inline constexpr Register kOpeningForce{0x05, 0x03};    ///< opening force, 20-100 %
inline constexpr Register kPosition{0x06, 0x02};        ///< 0-100 %, 100 = fully open
inline constexpr Register kRotation{0x07, 0x02};        ///< 0-100 % of 90 degrees
inline constexpr Register kGripStatus{0x0F, 0x01};      ///< read only, GripStatus
inline constexpr Register kRotationStatus{0x0F, 0x02};  ///< read only, RotationStatus
inline constexpr Register kCanId{0x12, 0x01};           ///< 1-255, reboot needed
inline constexpr Register kFirmwareVersion{0x13, 0x01}; ///< read only
inline constexpr Register kBaudRate{0x14, 0x01};        ///< index 0-5, reboot needed

inline constexpr Register kAll[] = {kInitFeedback, kInitialize,     kClosingForce,
                                    kOpeningForce, kPosition,       kRotation,
                                    kGripStatus,   kRotationStatus, kCanId,
                                    kFirmwareVersion, kBaudRate};
}  // namespace reg

/// The values the hand reports in 0x0F01 (the document's "grip status").
enum class GripStatus : std::int32_t {
  moving = 0,   ///< default, or still moving
  arrived = 2,  ///< reached the target without catching anything
  caught = 3,   ///< stopped on an object before the target
};
/// The values of 0x0F02: the same numbers, but the rotation is blocked, not caught.
enum class RotationStatus : std::int32_t {
  moving = 0,
  arrived = 2,
  blocked = 3,
};

/// Value written to 0x0801 to enable initialization feedback, and read back
/// when it is enabled (spec: receive `... 00 A5 00 00 00`).
inline constexpr std::int32_t kInitFeedbackEnabled = 0xA5;

struct ValueRange {
  std::int32_t min = 0;
  std::int32_t max = 0;
  [[nodiscard]] constexpr bool contains(std::int32_t v) const { return v >= min && v <= max; }
};

enum class RegisterError : std::uint8_t {
  unknown_register,  ///< not in the document's register map
  read_only,         ///< the register cannot be written (status, version)
  out_of_range,      ///< the value is outside the document's range
};

[[nodiscard]] std::string_view to_string(RegisterError error);

/// True if the register is one of the document's.
[[nodiscard]] bool is_known(Register r);
/// True if the document allows writing it.
[[nodiscard]] bool is_writable(Register r);
/// The range a write must fall in, or nullopt for registers that take no
/// range-checked value (0x0801, 0x0802) or cannot be written.
[[nodiscard]] std::optional<ValueRange> write_range(Register r);
/// Checks a write before anything is queued: known, writable, in range.
[[nodiscard]] Result<void, RegisterError> check_write(Register r, std::int32_t value);
/// Human name, e.g. "position" for 0x0602, "unknown" otherwise.
[[nodiscard]] std::string_view name(Register r);

/// Baud index (0x1401) to bits per second: 0 = 500 kbps ... 5 = 100 kbps.
[[nodiscard]] std::optional<std::uint32_t> baud_index_to_bps(std::int32_t index);

/// Firmware version 0x1301: the data's bytes from high to low joined by dots.
/// The document's `00 02 01 04` (little-endian 0x04010200) reads "4.1.2.0".
[[nodiscard]] std::string firmware_version_string(std::int32_t raw);

}  // namespace dh3::protocol
