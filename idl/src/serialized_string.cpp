#include "serialized_string.hpp"

namespace dh3::contract {

bool read_serialized_string(const unsigned char* data, std::uint32_t length, std::uint32_t& offset,
                            std::string_view& text) {
  // 4 bytes of encapsulation (CDR_BE 0x0000, CDR_LE 0x0001), then the members;
  // CDR aligns from the end of the encapsulation. A string: a 4-byte length
  // counting its terminating NUL, then its bytes.
  constexpr std::uint32_t kHeader = 4;
  if (data == nullptr || length < kHeader || data[0] != 0) return false;
  const bool little_endian = data[1] == 1;
  if (!little_endian && data[1] != 0) return false;
  offset = kHeader + ((offset - kHeader + 3U) & ~3U);
  if (offset > length || length - offset < 4) return false;
  const unsigned char* size_bytes = data + offset;
  const std::uint32_t size =
      little_endian ? (std::uint32_t{size_bytes[0]} | std::uint32_t{size_bytes[1]} << 8U |
                       std::uint32_t{size_bytes[2]} << 16U | std::uint32_t{size_bytes[3]} << 24U)
                    : (std::uint32_t{size_bytes[3]} | std::uint32_t{size_bytes[2]} << 8U |
                       std::uint32_t{size_bytes[1]} << 16U | std::uint32_t{size_bytes[0]} << 24U);
  if (size == 0 || size > length - offset - 4) return false;
  text = std::string_view(reinterpret_cast<const char*>(size_bytes + 4), size - 1);
  offset += 4 + size;
  return true;
}

}  // namespace dh3::contract
