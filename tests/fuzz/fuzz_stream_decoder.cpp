// libFuzzer target: the transfer-box stream decoder on arbitrary bytes.
// Beyond "does not crash", it checks what the decoder promises:
// - every frame it decodes is 14 bytes that really are in the input, in order
//   (it never builds a frame from bytes of different places);
// - how the stream is cut into reads does not change what is decoded;
// - it never holds a whole frame's worth of bytes back.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <vector>

#include "dh3/protocol/codec.hpp"
#include "dh3/protocol/stream_decoder.hpp"

namespace {

void check(bool condition) {
  if (!condition) std::abort();
}

bool appears_from(std::span<const std::uint8_t> data, std::size_t& from,
                  const dh3::protocol::BoxFrame& frame) {
  for (std::size_t i = from; i + frame.size() <= data.size(); ++i) {
    if (std::equal(frame.begin(), frame.end(), data.begin() + static_cast<std::ptrdiff_t>(i))) {
      from = i + frame.size();
      return true;
    }
  }
  return false;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* bytes, std::size_t size) {
  using namespace dh3::protocol;
  const std::span<const std::uint8_t> data(bytes, size);

  StreamDecoder whole;
  std::vector<Message> at_once;
  whole.feed(data, at_once);
  check(whole.buffered() < kBoxFrameSize);

  std::size_t from = 0;
  for (const Message& message : at_once) {
    check(appears_from(data, from, encode_box_frame(message)));
  }

  // The same bytes in reads whose sizes come from the data itself.
  StreamDecoder chunked;
  std::vector<Message> in_pieces;
  std::size_t offset = 0;
  std::size_t step = 1;
  while (offset < size) {
    const std::size_t length = std::min(size - offset, 1 + (bytes[offset] + step) % 17);
    chunked.feed(data.subspan(offset, length), in_pieces);
    check(chunked.buffered() < kBoxFrameSize);
    offset += length;
    ++step;
  }
  check(in_pieces == at_once);
  check(chunked.bytes_skipped() == whole.bytes_skipped());
  return 0;
}
