// StreamDecoder tests: frames split across reads, several per read, garbage in
// between (lone FB, truncated headers, headers inside junk, bad end bytes), and
// randomized chunking of long mixed streams that must yield exactly the frames sent.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <iterator>
#include <random>
#include <vector>

#include "dh3/protocol/codec.hpp"
#include "dh3/protocol/stream_decoder.hpp"

namespace dh3::protocol {
namespace {

using Bytes = std::vector<std::uint8_t>;

// Not stream.insert(stream.end(), ...): GCC 12 at -O3 warns falsely about
// that (-Warray-bounds inside libstdc++'s vector insert; GCC's meta-bug for
// such false positives is 56456).
void append(Bytes& stream, std::span<const std::uint8_t> bytes) {
  std::copy(bytes.begin(), bytes.end(), std::back_inserter(stream));
}

Bytes frame_bytes(const Message& message) {
  const BoxFrame frame = encode_box_frame(message);
  return Bytes(frame.begin(), frame.end());
}

std::vector<Message> feed_all(StreamDecoder& decoder, const Bytes& bytes) {
  std::vector<Message> out;
  decoder.feed(bytes, out);
  return out;
}

const Message kFrameA = make_write(1, reg::kPosition, 60);
const Message kFrameB = make_read(2, reg::kGripStatus);

TEST(StreamDecoder, SeveralFramesInOneRead) {
  Bytes stream;
  append(stream, frame_bytes(kFrameA));
  append(stream, frame_bytes(kFrameB));
  append(stream, frame_bytes(kFrameA));
  StreamDecoder decoder;
  EXPECT_EQ(feed_all(decoder, stream), (std::vector<Message>{kFrameA, kFrameB, kFrameA}));
  EXPECT_EQ(decoder.frames_decoded(), 3u);
  EXPECT_EQ(decoder.bytes_skipped(), 0u);
  EXPECT_EQ(decoder.buffered(), 0u);
}

TEST(StreamDecoder, FrameSplitAcrossReadsByteByByte) {
  const Bytes frame = frame_bytes(kFrameA);
  StreamDecoder decoder;
  std::vector<Message> out;
  for (std::size_t i = 0; i + 1 < frame.size(); ++i) {
    decoder.feed(std::span(frame).subspan(i, 1), out);
    EXPECT_TRUE(out.empty()) << "after byte " << i;
    EXPECT_EQ(decoder.buffered(), i + 1);
  }
  decoder.feed(std::span(frame).last(1), out);
  EXPECT_EQ(out, std::vector<Message>{kFrameA});
  EXPECT_EQ(decoder.buffered(), 0u);
  EXPECT_EQ(decoder.bytes_skipped(), 0u);
}

TEST(StreamDecoder, FrameSplitWithNextFrameStartingInSameRead) {
  Bytes stream = frame_bytes(kFrameA);
  append(stream, frame_bytes(kFrameB));
  StreamDecoder decoder;
  std::vector<Message> out;
  decoder.feed(std::span(stream).first(10), out);
  EXPECT_TRUE(out.empty());
  decoder.feed(std::span(stream).subspan(10, 10), out);  // end of A, start of B
  EXPECT_EQ(out, std::vector<Message>{kFrameA});
  EXPECT_EQ(decoder.buffered(), 6u);
  decoder.feed(std::span(stream).subspan(20), out);
  EXPECT_EQ(out, (std::vector<Message>{kFrameA, kFrameB}));
}

TEST(StreamDecoder, EmptyFeedDoesNothing) {
  StreamDecoder decoder;
  EXPECT_TRUE(feed_all(decoder, {}).empty());
  EXPECT_EQ(decoder.bytes_skipped(), 0u);
  EXPECT_EQ(decoder.buffered(), 0u);
}

TEST(StreamDecoder, LoneEndByteBetweenFramesIsSkipped) {
  Bytes stream = frame_bytes(kFrameA);
  stream.push_back(kBoxEnd);
  append(stream, frame_bytes(kFrameB));
  StreamDecoder decoder;
  EXPECT_EQ(feed_all(decoder, stream), (std::vector<Message>{kFrameA, kFrameB}));
  EXPECT_EQ(decoder.bytes_skipped(), 1u);
}

TEST(StreamDecoder, TruncatedHeaderThenRealFrame) {
  Bytes stream = {0xFF, 0xFE, 0xFD};
  append(stream, frame_bytes(kFrameA));
  StreamDecoder decoder;
  EXPECT_EQ(feed_all(decoder, stream), std::vector<Message>{kFrameA});
  EXPECT_EQ(decoder.bytes_skipped(), 3u);
  EXPECT_EQ(decoder.buffered(), 0u);
}

TEST(StreamDecoder, TruncatedHeaderInSeparateReadThenRealFrame) {
  const Bytes truncated = {0xFF, 0xFE, 0xFD};
  StreamDecoder decoder;
  std::vector<Message> out;
  decoder.feed(truncated, out);
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(decoder.buffered(), 3u);  // could still be a frame
  decoder.feed(frame_bytes(kFrameA), out);
  EXPECT_EQ(out, std::vector<Message>{kFrameA});
  EXPECT_EQ(decoder.bytes_skipped(), 3u);
}

TEST(StreamDecoder, PrefixThatCannotBeAFrameIsDroppedAtOnce) {
  StreamDecoder decoder;
  EXPECT_TRUE(feed_all(decoder, {0x00, 0x01, 0xFF, 0x00}).empty());
  EXPECT_EQ(decoder.buffered(), 0u);
  EXPECT_EQ(decoder.bytes_skipped(), 4u);
  // Header present but the access byte already says this is no frame.
  EXPECT_TRUE(feed_all(decoder, {0xFF, 0xFE, 0xFD, 0xFC, 0x01, 0x06, 0x02, 0x07}).empty());
  EXPECT_EQ(decoder.buffered(), 0u);
  EXPECT_EQ(decoder.bytes_skipped(), 12u);
}

TEST(StreamDecoder, HeaderInsideJunkWithBadAccessByte) {
  Bytes stream = {0x01, 0x02, 0xFF, 0xFE, 0xFD, 0xFC, 0x05, 0x06, 0x07, 0x08};
  append(stream, frame_bytes(kFrameB));
  StreamDecoder decoder;
  EXPECT_EQ(feed_all(decoder, stream), std::vector<Message>{kFrameB});
  EXPECT_EQ(decoder.bytes_skipped(), 10u);
}

TEST(StreamDecoder, HeaderInsideJunkWithValidAccessButNoEnd) {
  // Looks like the start of a frame up to the access byte; its byte 13 falls
  // inside the real frame that follows and is not FB.
  Bytes stream = {0x10, 0xFF, 0xFE, 0xFD, 0xFC, 0x01, 0x06, 0x02, 0x01, 0x00};
  append(stream, frame_bytes(kFrameA));
  StreamDecoder decoder;
  EXPECT_EQ(feed_all(decoder, stream), std::vector<Message>{kFrameA});
  EXPECT_EQ(decoder.bytes_skipped(), 10u);
}

TEST(StreamDecoder, FrameWithWrongEndThenGoodFrame) {
  Bytes bad = frame_bytes(kFrameB);
  bad.back() = 0xFA;
  Bytes stream = bad;
  append(stream, frame_bytes(kFrameA));
  StreamDecoder decoder;
  EXPECT_EQ(feed_all(decoder, stream), std::vector<Message>{kFrameA});
  EXPECT_EQ(decoder.bytes_skipped(), 14u);
}

TEST(StreamDecoder, FrameWithBadAccessThenGoodFrame) {
  Bytes bad = frame_bytes(kFrameB);
  bad[7] = 0x02;
  Bytes stream = bad;
  append(stream, frame_bytes(kFrameA));
  StreamDecoder decoder;
  EXPECT_EQ(feed_all(decoder, stream), std::vector<Message>{kFrameA});
  EXPECT_EQ(decoder.bytes_skipped(), 14u);
}

TEST(StreamDecoder, HeaderInsideCandidateIsFound) {
  // A truncated frame (header, id, register, access, reserve) runs into a real
  // frame; the bad candidate swallows the real header, so dropping the whole
  // candidate would lose the real frame.
  for (std::size_t cut = 1; cut < kBoxFrameSize; ++cut) {
    const Bytes truncated = frame_bytes(kFrameB);
    Bytes stream(truncated.begin(), truncated.begin() + static_cast<std::ptrdiff_t>(cut));
    append(stream, frame_bytes(kFrameA));
    append(stream, frame_bytes(kFrameB));
    StreamDecoder decoder;
    EXPECT_EQ(feed_all(decoder, stream), (std::vector<Message>{kFrameA, kFrameB}))
        << "cut " << cut << ": " << to_hex(stream);
    EXPECT_EQ(decoder.bytes_skipped(), cut);
  }
}

TEST(StreamDecoder, HeaderInsideCandidateAcrossReads) {
  const Bytes truncated = {0xFF, 0xFE, 0xFD, 0xFC, 0x02, 0x0F, 0x01, 0x00, 0x00};
  const Bytes real = frame_bytes(kFrameA);
  StreamDecoder decoder;
  std::vector<Message> out;
  decoder.feed(truncated, out);
  EXPECT_EQ(decoder.buffered(), truncated.size());
  decoder.feed(std::span(real).first(3), out);
  decoder.feed(std::span(real).subspan(3), out);
  EXPECT_EQ(out, std::vector<Message>{kFrameA});
  EXPECT_EQ(decoder.bytes_skipped(), truncated.size());
  EXPECT_EQ(decoder.buffered(), 0u);
}

TEST(StreamDecoder, RepeatedHeadersAreNotFrames) {
  Bytes stream;
  for (int i = 0; i < 50; ++i) append(stream, kBoxHeader);
  append(stream, frame_bytes(kFrameA));
  StreamDecoder decoder;
  EXPECT_EQ(feed_all(decoder, stream), std::vector<Message>{kFrameA});
  EXPECT_EQ(decoder.bytes_skipped(), 200u);
}

TEST(StreamDecoder, FramesFullOfMarkerBytesDecode) {
  // Frames whose id, register and data are header/end bytes must not confuse resync.
  const Message tricky{0xFF, Register{0xFE, 0xFD}, Access::write, 0xFC, -1};
  const Message tricky2{0xFB, Register{0xFB, 0xFF}, Access::read, 0xFB, 0x7BFFFEFD};
  Bytes stream = frame_bytes(tricky);
  append(stream, frame_bytes(tricky2));
  append(stream, frame_bytes(tricky));
  StreamDecoder decoder;
  EXPECT_EQ(feed_all(decoder, stream), (std::vector<Message>{tricky, tricky2, tricky}));
  EXPECT_EQ(decoder.bytes_skipped(), 0u);
}

TEST(StreamDecoder, ResetForgetsPartialFrame) {
  const Bytes frame = frame_bytes(kFrameA);
  StreamDecoder decoder;
  std::vector<Message> out;
  decoder.feed(std::span(frame).first(9), out);
  EXPECT_EQ(decoder.buffered(), 9u);
  decoder.reset();
  EXPECT_EQ(decoder.buffered(), 0u);
  EXPECT_EQ(decoder.bytes_skipped(), 9u);
  // The rest of the old frame is junk now; the next whole frame still decodes.
  decoder.feed(std::span(frame).subspan(9), out);
  decoder.feed(frame_bytes(kFrameB), out);
  EXPECT_EQ(out, std::vector<Message>{kFrameB});
  EXPECT_EQ(decoder.bytes_skipped(), 14u);
}

TEST(StreamDecoder, LongGarbageInSmallChunksThenFrame) {
  // A megabyte of 0xFF (every byte a possible frame start) and of other junk:
  // linear work keeps this quick; a quadratic decoder would hit the test timeout.
  Bytes stream(1 << 20, 0xFF);
  stream.resize(2 << 20, 0xFC);  // not insert(): as append() above
  append(stream, frame_bytes(kFrameA));
  StreamDecoder decoder;
  std::vector<Message> out;
  constexpr std::size_t kChunk = 100;
  for (std::size_t i = 0; i < stream.size(); i += kChunk) {
    decoder.feed(std::span(stream).subspan(i, std::min(kChunk, stream.size() - i)), out);
    ASSERT_LT(decoder.buffered(), kBoxFrameSize);
  }
  EXPECT_EQ(out, std::vector<Message>{kFrameA});
  EXPECT_EQ(decoder.bytes_skipped(), 2u << 20);
}

TEST(StreamDecoder, LongGarbageInOneRead) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> non_ff(0x00, 0xFE);
  Bytes stream;
  for (int i = 0; i < (1 << 21); ++i) stream.push_back(static_cast<std::uint8_t>(non_ff(rng)));
  append(stream, frame_bytes(kFrameB));
  StreamDecoder decoder;
  EXPECT_EQ(feed_all(decoder, stream), std::vector<Message>{kFrameB});
  EXPECT_EQ(decoder.bytes_skipped(), 1u << 21);
}

// --- randomized streams ---------------------------------------------------------

Message random_message(std::mt19937& rng) {
  std::uniform_int_distribution<int> byte(0, 255);
  std::uniform_int_distribution<std::int32_t> value(std::numeric_limits<std::int32_t>::min(),
                                                    std::numeric_limits<std::int32_t>::max());
  std::uniform_int_distribution<std::size_t> pick(0, std::size(reg::kAll));
  const std::size_t r = pick(rng);
  return Message{static_cast<std::uint8_t>(byte(rng)),
                 r < std::size(reg::kAll) ? reg::kAll[r]
                                          : Register{static_cast<std::uint8_t>(byte(rng)),
                                                     static_cast<std::uint8_t>(byte(rng))},
                 byte(rng) % 2 == 0 ? Access::read : Access::write,
                 static_cast<std::uint8_t>(byte(rng)), value(rng)};
}

// A message whose bytes after the header hold no FF and no FB: placed right after
// a truncated frame, it cannot complete that fragment into a false frame (the
// fragment's byte 13 would fall on one of these bytes).
Message clean_message(std::mt19937& rng) {
  for (;;) {
    const Message message = random_message(rng);
    const BoxFrame frame = encode_box_frame(message);
    if (std::none_of(frame.begin() + 4, frame.end() - 1,
                     [](std::uint8_t b) { return b == 0xFF || b == kBoxEnd; })) {
      return message;
    }
  }
}

struct Stream {
  Bytes bytes;
  std::vector<Message> frames;
  std::uint64_t junk = 0;
};

// Frames interleaved with garbage. Plain garbage holds no 0xFF, so it can never
// start a frame; the adversarial fragments (lone FB, truncated header, truncated
// frame) are each followed directly by a clean frame so none can become one.
Stream make_stream(std::uint32_t seed, int frame_count) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> non_ff(0x00, 0xFE);
  std::uniform_int_distribution<int> junk_length(0, 20);
  std::uniform_int_distribution<int> kind(0, 5);
  std::uniform_int_distribution<std::size_t> cut(1, kBoxFrameSize - 1);
  Stream stream;
  const auto add_junk = [&](std::span<const std::uint8_t> junk) {
    append(stream.bytes, junk);
    stream.junk += junk.size();
  };
  for (int i = 0; i < frame_count; ++i) {
    Bytes junk;
    const int junk_bytes = junk_length(rng);
    for (int j = 0; j < junk_bytes; ++j) junk.push_back(static_cast<std::uint8_t>(non_ff(rng)));
    add_junk(junk);

    Message message;
    switch (kind(rng)) {
      case 0: {  // lone end byte
        add_junk(Bytes{kBoxEnd});
        message = clean_message(rng);
        break;
      }
      case 1: {  // truncated header
        add_junk(std::span(kBoxHeader).first(cut(rng) % 4));
        message = clean_message(rng);
        break;
      }
      case 2: {  // truncated frame whose byte 13 would fall in the next frame
        const BoxFrame cut_frame = encode_box_frame(clean_message(rng));
        add_junk(std::span(cut_frame).first(cut(rng)));
        message = clean_message(rng);
        break;
      }
      default:
        message = random_message(rng);
        break;
    }
    append(stream.bytes, frame_bytes(message));
    stream.frames.push_back(message);
  }
  return stream;
}

void expect_stream_decodes(std::uint32_t seed) {
  SCOPED_TRACE(::testing::Message() << "seed " << seed);
  const Stream stream = make_stream(seed, 3000);
  std::mt19937 rng(seed ^ 0x5A5A5A5AU);
  std::uniform_int_distribution<std::size_t> chunk_length(0, 40);
  StreamDecoder decoder;
  std::vector<Message> out;
  std::size_t offset = 0;
  while (offset < stream.bytes.size()) {
    const std::size_t length = std::min(chunk_length(rng), stream.bytes.size() - offset);
    decoder.feed(std::span(stream.bytes).subspan(offset, length), out);
    ASSERT_LT(decoder.buffered(), kBoxFrameSize);
    offset += length;
  }
  ASSERT_EQ(out.size(), stream.frames.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    ASSERT_EQ(out[i], stream.frames[i])
        << "frame " << i << ": got " << describe(out[i]) << ", sent " << describe(stream.frames[i]);
  }
  EXPECT_EQ(decoder.frames_decoded(), stream.frames.size());
  EXPECT_EQ(decoder.bytes_skipped(), stream.junk);
  EXPECT_EQ(decoder.buffered(), 0u);
}

TEST(StreamDecoderRandom, FixedSeed) {
  expect_stream_decodes(20240611u);
}

TEST(StreamDecoderRandom, SeveralSeeds) {
  for (const std::uint32_t seed : {1u, 2u, 42u, 0xC0FFEEu, 0xDEADBEEFu}) {
    expect_stream_decodes(seed);
  }
}

TEST(StreamDecoderRandom, WholeStreamInOneRead) {
  const Stream stream = make_stream(99u, 3000);
  StreamDecoder decoder;
  EXPECT_EQ(feed_all(decoder, stream.bytes), stream.frames);
  EXPECT_EQ(decoder.bytes_skipped(), stream.junk);
}

}  // namespace
}  // namespace dh3::protocol
