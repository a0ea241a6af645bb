// libFuzzer target: the 8-byte CAN payload codec. Whatever decodes must
// re-encode to the same bytes (except the read/write byte, which decodes only
// from 00 or 01), and out-of-range writes must be caught by check_write.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "dh3/protocol/codec.hpp"
#include "dh3/protocol/registers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* bytes, std::size_t size) {
  using namespace dh3::protocol;
  if (size < 1) return 0;
  const std::uint8_t hand_id = bytes[0];
  const auto payload = std::span<const std::uint8_t>(bytes + 1, size - 1);
  const auto decoded = decode_payload(hand_id, payload);
  if (!decoded) return 0;
  if (payload.size() != kPayloadSize) std::abort();
  const Payload again = encode_payload(*decoded);
  if (!std::equal(again.begin(), again.end(), payload.begin())) std::abort();
  const auto range = write_range(decoded->reg);
  const auto verdict = check_write(decoded->reg, decoded->data);
  if (range && !range->contains(decoded->data) && verdict.ok()) std::abort();
  return 0;
}
