#pragma once
// Finds 14-byte transfer-box frames in a byte stream (TCP, serial): frames split
// across reads, several frames in one read, and garbage between them (a lone FB,
// a truncated header, a header inside junk). A candidate is accepted only if it
// has the header, the end byte and a valid read/write byte; otherwise the decoder
// drops one byte and searches again, so it never decodes a wrong frame from the
// middle of a good one it could still find.

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "dh3/protocol/codec.hpp"

namespace dh3::protocol {

class StreamDecoder {
 public:
  /// Appends every complete frame found in `bytes` (plus what was buffered) to `out`.
  void feed(std::span<const std::uint8_t> bytes, std::vector<Message>& out);

  /// Bytes thrown away as not belonging to any valid frame, since construction.
  [[nodiscard]] std::uint64_t bytes_skipped() const { return bytes_skipped_; }
  /// Frames decoded since construction.
  [[nodiscard]] std::uint64_t frames_decoded() const { return frames_decoded_; }
  /// Bytes held while waiting for the rest of a frame (always < 14).
  [[nodiscard]] std::size_t buffered() const { return buffer_.size(); }
  /// Forgets a partial frame, e.g. after the link reconnects; its bytes count as skipped.
  void reset() {
    bytes_skipped_ += buffer_.size();
    buffer_.clear();
  }

 private:
  std::vector<std::uint8_t> buffer_;
  std::uint64_t bytes_skipped_ = 0;
  std::uint64_t frames_decoded_ = 0;
};

}  // namespace dh3::protocol
