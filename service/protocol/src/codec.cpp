#include "dh3/protocol/codec.hpp"

#include <algorithm>
#include <cstdio>

namespace dh3::protocol {

namespace {

// Offsets inside the 8-byte data segment (spec: "Protocol format").
constexpr std::size_t kFunctionOffset = 0;
constexpr std::size_t kSubFunctionOffset = 1;
constexpr std::size_t kAccessOffset = 2;
constexpr std::size_t kReserveOffset = 3;
constexpr std::size_t kDataOffset = 4;

// Offsets inside the 14-byte transfer-box frame.
constexpr std::size_t kBoxHandIdOffset = 4;
constexpr std::size_t kBoxPayloadOffset = 5;
constexpr std::size_t kBoxEndOffset = kBoxFrameSize - 1;

void write_payload(const Message& message, std::span<std::uint8_t, kPayloadSize> out) {
  out[kFunctionOffset] = message.reg.function;
  out[kSubFunctionOffset] = message.reg.sub_function;
  out[kAccessOffset] = static_cast<std::uint8_t>(message.access);
  out[kReserveOffset] = message.reserve;
  // Two's complement, little endian, all 32 bits (docs/protocol-notes.md reading 8).
  const auto bits = static_cast<std::uint32_t>(message.data);
  for (std::size_t i = 0; i < 4; ++i) {
    out[kDataOffset + i] = static_cast<std::uint8_t>((bits >> (8 * i)) & 0xFFU);
  }
}

Result<Message, DecodeError> read_payload(std::uint8_t hand_id,
                                          std::span<const std::uint8_t, kPayloadSize> in) {
  const std::uint8_t access = in[kAccessOffset];
  if (access != static_cast<std::uint8_t>(Access::read) &&
      access != static_cast<std::uint8_t>(Access::write)) {
    return fail(DecodeError::bad_access);
  }
  std::uint32_t bits = 0;
  for (std::size_t i = 0; i < 4; ++i) {
    bits |= static_cast<std::uint32_t>(in[kDataOffset + i]) << (8 * i);
  }
  Message message;
  message.hand_id = hand_id;
  message.reg = Register{in[kFunctionOffset], in[kSubFunctionOffset]};
  message.access = static_cast<Access>(access);
  message.reserve = in[kReserveOffset];
  message.data = static_cast<std::int32_t>(bits);  // well defined since C++20
  return message;
}

}  // namespace

std::string_view to_string(DecodeError error) {
  switch (error) {
    case DecodeError::wrong_size:
      return "wrong_size";
    case DecodeError::bad_header:
      return "bad_header";
    case DecodeError::bad_end:
      return "bad_end";
    case DecodeError::bad_access:
      return "bad_access";
  }
  return "invalid DecodeError";
}

Payload encode_payload(const Message& message) {
  Payload payload{};
  write_payload(message, payload);
  return payload;
}

Result<Message, DecodeError> decode_payload(std::uint8_t hand_id,
                                            std::span<const std::uint8_t> payload) {
  if (payload.size() != kPayloadSize) return fail(DecodeError::wrong_size);
  return read_payload(hand_id, payload.first<kPayloadSize>());
}

BoxFrame encode_box_frame(const Message& message) {
  BoxFrame frame{};
  std::copy(kBoxHeader.begin(), kBoxHeader.end(), frame.begin());
  frame[kBoxHandIdOffset] = message.hand_id;
  write_payload(message, std::span(frame).subspan<kBoxPayloadOffset, kPayloadSize>());
  frame[kBoxEndOffset] = kBoxEnd;
  return frame;
}

Result<Message, DecodeError> decode_box_frame(std::span<const std::uint8_t> frame) {
  if (frame.size() != kBoxFrameSize) return fail(DecodeError::wrong_size);
  if (!std::equal(kBoxHeader.begin(), kBoxHeader.end(), frame.begin())) {
    return fail(DecodeError::bad_header);
  }
  if (frame[kBoxEndOffset] != kBoxEnd) return fail(DecodeError::bad_end);
  return read_payload(frame[kBoxHandIdOffset],
                      frame.subspan(kBoxPayloadOffset).first<kPayloadSize>());
}

std::int32_t status_value(const Message& reply) {
  if (reply.data == 0 && reply.reserve != 0) return reply.reserve;
  return reply.data;
}

std::string to_hex(std::span<const std::uint8_t> bytes) {
  static constexpr char kDigits[] = "0123456789ABCDEF";
  std::string text;
  text.reserve(bytes.size() * 3);
  for (const std::uint8_t byte : bytes) {
    if (!text.empty()) text += ' ';
    text += kDigits[byte >> 4];
    text += kDigits[byte & 0x0F];
  }
  return text;
}

std::string describe(const Message& message) {
  char code[8];
  std::snprintf(code, sizeof code, "0x%04X", static_cast<unsigned>(message.reg.code()));
  std::string text = "hand " + std::to_string(message.hand_id);
  text += message.access == Access::write ? " write " : " read ";
  text += name(message.reg);
  text += '(';
  text += code;
  text += ')';
  text += " = " + std::to_string(message.data);
  if (message.reserve != 0) text += " reserve " + std::to_string(message.reserve);
  return text;
}

}  // namespace dh3::protocol
