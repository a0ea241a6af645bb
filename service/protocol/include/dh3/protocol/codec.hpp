#pragma once
// Encoding and decoding of DH-3 messages: the 8-byte CAN payload and the
// 14-byte transfer-box frame (spec: "Protocol format"). Pure: no I/O, no clock.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "dh3/base/result.hpp"
#include "dh3/protocol/registers.hpp"

namespace dh3::protocol {

enum class Access : std::uint8_t { read = 0x00, write = 0x01 };

/// One DH-3 message, as a command or as the hand's reply. `hand_id` is the CAN
/// ID (CAN 2.0A) or the transfer box's gripper-ID byte.
struct Message {
  std::uint8_t hand_id = 0;
  Register reg{};
  Access access = Access::read;
  std::uint8_t reserve = 0;  ///< always 0 in what we send; see docs/protocol-notes.md reading 2
  std::int32_t data = 0;     ///< signed 32-bit, little endian on the wire

  friend constexpr bool operator==(const Message&, const Message&) = default;
};

inline constexpr std::size_t kPayloadSize = 8;
inline constexpr std::size_t kBoxFrameSize = 14;
inline constexpr std::array<std::uint8_t, 4> kBoxHeader{0xFF, 0xFE, 0xFD, 0xFC};
inline constexpr std::uint8_t kBoxEnd = 0xFB;

using Payload = std::array<std::uint8_t, kPayloadSize>;
using BoxFrame = std::array<std::uint8_t, kBoxFrameSize>;

enum class DecodeError : std::uint8_t {
  wrong_size,    ///< not 8 (payload) or 14 (frame) bytes
  bad_header,    ///< frame does not start with FF FE FD FC
  bad_end,       ///< frame does not end with FB
  bad_access,    ///< read/write byte is neither 00 nor 01
};

[[nodiscard]] std::string_view to_string(DecodeError error);

[[nodiscard]] Payload encode_payload(const Message& message);
/// `hand_id` comes from the CAN identifier, which the payload does not carry.
[[nodiscard]] Result<Message, DecodeError> decode_payload(std::uint8_t hand_id,
                                                          std::span<const std::uint8_t> payload);

[[nodiscard]] BoxFrame encode_box_frame(const Message& message);
[[nodiscard]] Result<Message, DecodeError> decode_box_frame(std::span<const std::uint8_t> frame);

/// Convenience builders for what the service sends.
[[nodiscard]] constexpr Message make_read(std::uint8_t hand_id, Register r) {
  return Message{hand_id, r, Access::read, 0, 0};
}
[[nodiscard]] constexpr Message make_write(std::uint8_t hand_id, Register r, std::int32_t value) {
  return Message{hand_id, r, Access::write, 0, value};
}

/// The value a status reply carries, per docs/protocol-notes.md reading 2: the data field,
/// or, when the data field is zero and the reserve byte is not, the reserve byte
/// (the document's own "arrived"/"caught" examples).
[[nodiscard]] std::int32_t status_value(const Message& reply);

/// "FF FE FD FC 01 ..." for logs and test messages.
[[nodiscard]] std::string to_hex(std::span<const std::uint8_t> bytes);
/// "hand 1 write position(0x0602) = 60" for logs.
[[nodiscard]] std::string describe(const Message& message);

}  // namespace dh3::protocol
