#include "dh3/protocol/stream_decoder.hpp"

#include <algorithm>

namespace dh3::protocol {

namespace {

constexpr std::size_t kAccessOffsetInFrame = 7;  // header 4 + id 1 + function 1 + sub 1
constexpr std::size_t kEndOffsetInFrame = kBoxFrameSize - 1;

enum class Candidate { invalid, incomplete, complete };

// Judges the bytes starting at a possible frame start using only what has
// arrived so far: a prefix that already contradicts the frame layout is
// rejected at once instead of being held until 14 bytes are in.
Candidate judge(std::span<const std::uint8_t> bytes) {
  const std::size_t header_bytes = std::min(bytes.size(), kBoxHeader.size());
  if (!std::equal(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(header_bytes),
                  kBoxHeader.begin())) {
    return Candidate::invalid;
  }
  if (bytes.size() > kAccessOffsetInFrame) {
    const std::uint8_t access = bytes[kAccessOffsetInFrame];
    if (access != static_cast<std::uint8_t>(Access::read) &&
        access != static_cast<std::uint8_t>(Access::write)) {
      return Candidate::invalid;
    }
  }
  if (bytes.size() > kEndOffsetInFrame && bytes[kEndOffsetInFrame] != kBoxEnd) {
    return Candidate::invalid;
  }
  return bytes.size() >= kBoxFrameSize ? Candidate::complete : Candidate::incomplete;
}

}  // namespace

void StreamDecoder::feed(std::span<const std::uint8_t> bytes, std::vector<Message>& out) {
  buffer_.insert(buffer_.end(), bytes.begin(), bytes.end());

  const auto begin = buffer_.begin();
  const auto end = buffer_.end();
  auto cursor = begin;
  while (cursor != end) {
    // Every frame starts with 0xFF: jump straight to the next one, so long
    // garbage costs one linear scan.
    const auto start = std::find(cursor, end, kBoxHeader[0]);
    bytes_skipped_ += static_cast<std::uint64_t>(start - cursor);
    cursor = start;
    if (cursor == end) break;

    const std::span<const std::uint8_t> rest(&*cursor, static_cast<std::size_t>(end - cursor));
    const Candidate candidate = judge(rest);
    if (candidate == Candidate::incomplete) break;
    if (candidate == Candidate::complete) {
      auto message = decode_box_frame(rest.first(kBoxFrameSize));
      if (message) {
        out.push_back(*message);
        ++frames_decoded_;
        cursor += static_cast<std::ptrdiff_t>(kBoxFrameSize);
        continue;
      }
    }
    // Drop only this byte: a real header may start inside the rejected candidate.
    ++bytes_skipped_;
    ++cursor;
  }
  buffer_.erase(begin, cursor);
}

}  // namespace dh3::protocol
