// Codec tests: every byte example of docs/dh3-protocol.md, both directions,
// plus randomized round trips and the decoder's rejections.

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "dh3/protocol/codec.hpp"

namespace dh3::protocol {
namespace {

std::vector<std::uint8_t> from_hex(const std::string& text) {
  std::vector<std::uint8_t> bytes;
  std::istringstream in(text);
  std::string token;
  while (in >> token) bytes.push_back(static_cast<std::uint8_t>(std::stoul(token, nullptr, 16)));
  return bytes;
}

Message msg(std::uint8_t hand_id, Register r, Access access, std::uint8_t reserve,
            std::int32_t data) {
  return Message{hand_id, r, access, reserve, data};
}

constexpr Access R = Access::read;
constexpr Access W = Access::write;

struct SpecExample {
  const char* label;  // test name suffix
  const char* hex;    // verbatim from the document
  Message expected;
};

// Every frame the document prints, in document order. Duplicates are kept on
// purpose: each line of the document is its own case.
const SpecExample kSpecExamples[] = {
    {"FormatExampleInitialization", "FF FE FD FC 01 08 02 01 00 00 00 00 00 FB",
     msg(1, reg::kInitialize, W, 0, 0)},
    {"SetInitFeedbackSend", "FF FE FD FC 01 08 01 01 00 00 00 00 00 FB",
     msg(1, reg::kInitFeedback, W, 0, 0)},
    {"SetInitFeedbackReceive", "FF FE FD FC 01 08 01 01 00 A5 00 00 00 FB",
     msg(1, reg::kInitFeedback, W, 0, kInitFeedbackEnabled)},
    {"ReadInitFeedbackSend", "FF FE FD FC 01 08 01 00 00 00 00 00 00 FB",
     msg(1, reg::kInitFeedback, R, 0, 0)},
    {"ReadInitFeedbackReceiveYes", "FF FE FD FC 01 08 01 00 00 A5 00 00 00 FB",
     msg(1, reg::kInitFeedback, R, 0, kInitFeedbackEnabled)},
    {"ReadInitFeedbackReceiveNo", "FF FE FD FC 01 08 01 00 00 00 00 00 00 FB",
     msg(1, reg::kInitFeedback, R, 0, 0)},
    {"InitializeSend", "FF FE FD FC 01 08 02 01 00 00 00 00 00 FB",
     msg(1, reg::kInitialize, W, 0, 0)},
    {"InitializeReceive", "FF FE FD FC 01 08 02 01 00 00 00 00 00 FB",
     msg(1, reg::kInitialize, W, 0, 0)},
    {"InitializeUnsolicitedFeedback", "FF FE FD FC 01 08 02 00 00 00 00 00 00 FB",
     msg(1, reg::kInitialize, R, 0, 0)},
    {"ReadInitFinishedSend", "FF FE FD FC 01 08 02 00 00 00 00 00 00 FB",
     msg(1, reg::kInitialize, R, 0, 0)},
    {"ReadInitFinishedReceiveFinished", "FF FE FD FC 01 08 02 00 00 01 00 00 00 FB",
     msg(1, reg::kInitialize, R, 0, 1)},
    {"ReadInitFinishedReceiveNotFinished", "FF FE FD FC 01 08 02 00 00 00 00 00 00 FB",
     msg(1, reg::kInitialize, R, 0, 0)},
    {"SetForceSend", "FF FE FD FC 01 05 02 01 00 1E 00 00 00 FB",
     msg(1, reg::kClosingForce, W, 0, 30)},
    {"SetForceReceive", "FF FE FD FC 01 05 02 01 00 1E 00 00 00 FB",
     msg(1, reg::kClosingForce, W, 0, 30)},
    {"ReadForceSend", "FF FE FD FC 01 05 02 00 00 00 00 00 00 FB",
     msg(1, reg::kClosingForce, R, 0, 0)},
    {"ReadForceReceive", "FF FE FD FC 01 05 02 00 00 1E 00 00 00 FB",
     msg(1, reg::kClosingForce, R, 0, 30)},
    {"SetPositionSend", "FF FE FD FC 01 06 02 01 00 3C 00 00 00 FB",
     msg(1, reg::kPosition, W, 0, 60)},
    {"SetPositionReceive", "FF FE FD FC 01 06 02 01 00 3C 00 00 00 FB",
     msg(1, reg::kPosition, W, 0, 60)},
    {"ReadPositionSend", "FF FE FD FC 01 06 02 00 00 00 00 00 00 FB",
     msg(1, reg::kPosition, R, 0, 0)},
    {"ReadPositionReceive", "FF FE FD FC 01 06 02 00 00 3C 00 00 00 FB",
     msg(1, reg::kPosition, R, 0, 60)},
    {"SetRotationSend", "FF FE FD FC 01 07 02 01 00 43 00 00 00 FB",
     msg(1, reg::kRotation, W, 0, 67)},
    {"SetRotationReceive", "FF FE FD FC 01 07 02 01 00 43 00 00 00 FB",
     msg(1, reg::kRotation, W, 0, 67)},
    {"ReadRotationSend", "FF FE FD FC 01 07 02 00 00 00 00 00 00 FB",
     msg(1, reg::kRotation, R, 0, 0)},
    {"ReadRotationReceive", "FF FE FD FC 01 07 02 00 00 43 00 00 00 FB",
     msg(1, reg::kRotation, R, 0, 67)},
    {"ReadGripStatusSend", "FF FE FD FC 01 0F 01 00 00 00 00 00 00 FB",
     msg(1, reg::kGripStatus, R, 0, 0)},
    {"ReadGripStatusReceiveDefault", "FF FE FD FC 01 0F 01 00 00 00 00 00 00 FB",
     msg(1, reg::kGripStatus, R, 0, 0)},
    {"ReadGripStatusReceiveArrived", "FF FE FD FC 01 0F 01 00 02 00 00 00 00 FB",
     msg(1, reg::kGripStatus, R, 2, 0)},
    {"ReadGripStatusReceiveCaught", "FF FE FD FC 01 0F 01 00 03 00 00 00 00 FB",
     msg(1, reg::kGripStatus, R, 3, 0)},
    {"ReadRotationStatusSend", "FF FE FD FC 01 0F 02 00 00 00 00 00 00 FB",
     msg(1, reg::kRotationStatus, R, 0, 0)},
    {"ReadRotationStatusReceiveDefault", "FF FE FD FC 01 0F 02 00 00 00 00 00 00 FB",
     msg(1, reg::kRotationStatus, R, 0, 0)},
    {"ReadRotationStatusReceiveArrived", "FF FE FD FC 01 0F 02 00 02 00 00 00 00 FB",
     msg(1, reg::kRotationStatus, R, 2, 0)},
    {"ReadRotationStatusReceiveCaught", "FF FE FD FC 01 0F 02 00 03 00 00 00 00 FB",
     msg(1, reg::kRotationStatus, R, 3, 0)},
    {"SetCanIdFrom1Send", "FF FE FD FC 01 12 01 01 00 02 00 00 00 FB",
     msg(1, reg::kCanId, W, 0, 2)},
    {"SetCanIdFrom1Receive", "FF FE FD FC 01 12 01 01 00 02 00 00 00 FB",
     msg(1, reg::kCanId, W, 0, 2)},
    {"SetCanIdWithId0Send", "FF FE FD FC 00 12 01 01 00 02 00 00 00 FB",
     msg(0, reg::kCanId, W, 0, 2)},
    {"SetCanIdWithId0Receive", "FF FE FD FC 00 12 01 01 00 02 00 00 00 FB",
     msg(0, reg::kCanId, W, 0, 2)},
    {"ReadCanIdSend", "FF FE FD FC 02 12 01 00 00 00 00 00 00 FB", msg(2, reg::kCanId, R, 0, 0)},
    {"ReadCanIdReceive", "FF FE FD FC 02 12 01 00 00 02 00 00 00 FB", msg(2, reg::kCanId, R, 0, 2)},
    // The document's "read" with ID 0 carries the write flag (docs/protocol-notes.md reading 1):
    // it decodes faithfully as a write; matching replies ignores that byte.
    {"ReadCanIdWithId0Send", "FF FE FD FC 00 12 01 01 00 00 00 00 00 FB",
     msg(0, reg::kCanId, W, 0, 0)},
    {"ReadCanIdWithId0Receive", "FF FE FD FC 00 12 01 01 00 02 00 00 00 FB",
     msg(0, reg::kCanId, W, 0, 2)},
    {"ReadFirmwareVersionSend", "FF FE FD FC 01 13 01 00 00 00 00 00 00 FB",
     msg(1, reg::kFirmwareVersion, R, 0, 0)},
    {"ReadFirmwareVersionReceive", "FF FE FD FC 01 13 01 00 00 00 02 01 04 FB",
     msg(1, reg::kFirmwareVersion, R, 0, 0x04010200)},
    {"SetBaudRateSend", "FF FE FD FC 01 14 01 01 00 02 00 00 00 FB",
     msg(1, reg::kBaudRate, W, 0, 2)},
    {"SetBaudRateReceive", "FF FE FD FC 01 14 01 01 00 02 00 00 00 FB",
     msg(1, reg::kBaudRate, W, 0, 2)},
    {"ReadBaudRateSend", "FF FE FD FC 01 14 01 00 00 00 00 00 00 FB",
     msg(1, reg::kBaudRate, R, 0, 0)},
    {"ReadBaudRateReceive", "FF FE FD FC 01 14 01 00 00 02 00 00 00 FB",
     msg(1, reg::kBaudRate, R, 0, 2)},
};

class SpecExampleTest : public ::testing::TestWithParam<SpecExample> {};

TEST_P(SpecExampleTest, BoxFrameDecodesToExpectedMessage) {
  const SpecExample& example = GetParam();
  const std::vector<std::uint8_t> bytes = from_hex(example.hex);
  ASSERT_EQ(bytes.size(), kBoxFrameSize);
  const auto decoded = decode_box_frame(bytes);
  ASSERT_TRUE(decoded.ok()) << to_string(decoded.error());
  EXPECT_EQ(*decoded, example.expected) << describe(*decoded);
}

TEST_P(SpecExampleTest, BoxFrameReencodesToSameBytes) {
  const SpecExample& example = GetParam();
  const BoxFrame frame = encode_box_frame(example.expected);
  EXPECT_EQ(to_hex(frame), example.hex);
}

TEST_P(SpecExampleTest, CanPayloadIsFrameBytes5To12) {
  const SpecExample& example = GetParam();
  const std::vector<std::uint8_t> bytes = from_hex(example.hex);
  ASSERT_EQ(bytes.size(), kBoxFrameSize);
  const std::span<const std::uint8_t> frame_payload = std::span(bytes).subspan(5, kPayloadSize);

  const Payload payload = encode_payload(example.expected);
  EXPECT_EQ(to_hex(payload), to_hex(frame_payload));

  const auto decoded = decode_payload(example.expected.hand_id, frame_payload);
  ASSERT_TRUE(decoded.ok()) << to_string(decoded.error());
  EXPECT_EQ(*decoded, example.expected);
}

INSTANTIATE_TEST_SUITE_P(Document, SpecExampleTest, ::testing::ValuesIn(kSpecExamples),
                         [](const ::testing::TestParamInfo<SpecExample>& param_info) {
                           return std::string(param_info.param.label);
                         });

TEST(CodecSpec, InitializationExampleIsWhatMakeWriteBuilds) {
  EXPECT_EQ(to_hex(encode_box_frame(make_write(1, reg::kInitialize, 0))),
            "FF FE FD FC 01 08 02 01 00 00 00 00 00 FB");
  EXPECT_EQ(to_hex(encode_box_frame(make_read(1, reg::kPosition))),
            "FF FE FD FC 01 06 02 00 00 00 00 00 00 FB");
  EXPECT_EQ(to_hex(encode_box_frame(make_write(1, reg::kPosition, 60))),
            "FF FE FD FC 01 06 02 01 00 3C 00 00 00 FB");
}

TEST(CodecSpec, ReadCanIdWithId0DecodesAsWriteWithSameRegister) {
  // Reading 1: the frame decodes (it is not rejected) and names hand 0, 0x1201.
  const auto sent = decode_box_frame(from_hex("FF FE FD FC 00 12 01 01 00 00 00 00 00 FB"));
  const auto received = decode_box_frame(from_hex("FF FE FD FC 00 12 01 01 00 02 00 00 00 FB"));
  ASSERT_TRUE(sent.ok());
  ASSERT_TRUE(received.ok());
  EXPECT_EQ(sent->access, Access::write);
  EXPECT_EQ(received->hand_id, 0);
  EXPECT_EQ(received->reg, reg::kCanId);
  EXPECT_EQ(received->data, 2);
}

TEST(CodecSpec, FirmwareVersionReplyReadsAs4120) {
  const auto reply = decode_box_frame(from_hex("FF FE FD FC 01 13 01 00 00 00 02 01 04 FB"));
  ASSERT_TRUE(reply.ok());
  EXPECT_EQ(reply->data, 0x04010200);
  EXPECT_EQ(firmware_version_string(reply->data), "4.1.2.0");
}

TEST(StatusValue, DocumentArrivedAndCaughtUseReserveByte) {
  const auto arrived = decode_box_frame(from_hex("FF FE FD FC 01 0F 01 00 02 00 00 00 00 FB"));
  const auto caught = decode_box_frame(from_hex("FF FE FD FC 01 0F 01 00 03 00 00 00 00 FB"));
  const auto rot_arrived = decode_box_frame(from_hex("FF FE FD FC 01 0F 02 00 02 00 00 00 00 FB"));
  const auto rot_caught = decode_box_frame(from_hex("FF FE FD FC 01 0F 02 00 03 00 00 00 00 FB"));
  const auto moving = decode_box_frame(from_hex("FF FE FD FC 01 0F 01 00 00 00 00 00 00 FB"));
  ASSERT_TRUE(arrived && caught && rot_arrived && rot_caught && moving);
  EXPECT_EQ(status_value(*arrived), static_cast<std::int32_t>(GripStatus::arrived));
  EXPECT_EQ(status_value(*caught), static_cast<std::int32_t>(GripStatus::caught));
  EXPECT_EQ(status_value(*rot_arrived), 2);
  EXPECT_EQ(status_value(*rot_caught), 3);
  EXPECT_EQ(status_value(*moving), static_cast<std::int32_t>(GripStatus::moving));
}

TEST(StatusValue, DataFieldVariantIsRead) {
  // What the vendor's driver expects real hands to send: status in the data field.
  const auto arrived = decode_box_frame(from_hex("FF FE FD FC 01 0F 01 00 00 02 00 00 00 FB"));
  const auto caught = decode_box_frame(from_hex("FF FE FD FC 01 0F 02 00 00 03 00 00 00 FB"));
  ASSERT_TRUE(arrived && caught);
  EXPECT_EQ(status_value(*arrived), 2);
  EXPECT_EQ(status_value(*caught), 3);
}

TEST(StatusValue, DataFieldWinsWhenBothAreSet) {
  EXPECT_EQ(status_value(msg(1, reg::kGripStatus, R, 2, 3)), 3);
  EXPECT_EQ(status_value(msg(1, reg::kGripStatus, R, 0, 0)), 0);
}

TEST(CodecData, SignedLittleEndianFull32Bits) {
  // Reading 8: -1 is FF FF FF FF, nothing is truncated to 16 bits.
  EXPECT_EQ(to_hex(encode_payload(make_write(1, reg::kPosition, -1))), "06 02 01 00 FF FF FF FF");
  EXPECT_EQ(to_hex(encode_payload(make_write(1, reg::kPosition, 1))), "06 02 01 00 01 00 00 00");
  EXPECT_EQ(to_hex(encode_payload(make_write(1, reg::kPosition, 0x12345678))),
            "06 02 01 00 78 56 34 12");
  EXPECT_EQ(to_hex(encode_payload(make_write(1, reg::kPosition, 70000))),
            "06 02 01 00 70 11 01 00");
  EXPECT_EQ(to_hex(encode_payload(
                make_write(1, reg::kPosition, std::numeric_limits<std::int32_t>::min()))),
            "06 02 01 00 00 00 00 80");

  const auto decoded = decode_payload(1, from_hex("06 02 01 00 70 11 01 00"));
  ASSERT_TRUE(decoded.ok());
  EXPECT_EQ(decoded->data, 70000);
  const auto negative = decode_payload(1, from_hex("06 02 01 00 FE FF FF FF"));
  ASSERT_TRUE(negative.ok());
  EXPECT_EQ(negative->data, -2);
}

TEST(CodecRoundTrip, RandomValuesAllRegistersBothEncodings) {
  std::vector<std::int32_t> values = {0,
                                      1,
                                      -1,
                                      255,
                                      256,
                                      65535,
                                      65536,
                                      -32768,
                                      std::numeric_limits<std::int32_t>::min(),
                                      std::numeric_limits<std::int32_t>::max()};
  std::mt19937 rng(20240611);
  std::uniform_int_distribution<std::int32_t> any_int(std::numeric_limits<std::int32_t>::min(),
                                                      std::numeric_limits<std::int32_t>::max());
  for (int i = 0; i < 2000; ++i) values.push_back(any_int(rng));

  std::uniform_int_distribution<int> any_byte(0, 255);
  for (const Register r : reg::kAll) {
    for (const std::int32_t value : values) {
      for (const Access access : {Access::read, Access::write}) {
        const Message original{static_cast<std::uint8_t>(any_byte(rng)), r, access,
                               static_cast<std::uint8_t>(any_byte(rng)), value};
        const auto from_frame = decode_box_frame(encode_box_frame(original));
        ASSERT_TRUE(from_frame.ok()) << describe(original);
        ASSERT_EQ(*from_frame, original) << describe(original);

        const auto from_payload = decode_payload(original.hand_id, encode_payload(original));
        ASSERT_TRUE(from_payload.ok()) << describe(original);
        ASSERT_EQ(*from_payload, original) << describe(original);
      }
    }
  }
}

TEST(CodecRoundTrip, UnknownRegistersStillRoundTrip) {
  // The codec carries any (function, sub-function); judging them is check_write's job.
  const Message odd{7, Register{0xAB, 0xCD}, Access::read, 0, 42};
  const auto decoded = decode_box_frame(encode_box_frame(odd));
  ASSERT_TRUE(decoded.ok());
  EXPECT_EQ(*decoded, odd);
}

TEST(CodecDecode, RejectsWrongSize) {
  const BoxFrame good = encode_box_frame(make_write(1, reg::kPosition, 60));
  const std::span<const std::uint8_t> all(good);
  EXPECT_EQ(decode_box_frame(all.first(13)).error(), DecodeError::wrong_size);
  EXPECT_EQ(decode_box_frame({}).error(), DecodeError::wrong_size);
  std::vector<std::uint8_t> longer(good.begin(), good.end());
  longer.push_back(0x00);
  EXPECT_EQ(decode_box_frame(longer).error(), DecodeError::wrong_size);

  const Payload payload = encode_payload(make_write(1, reg::kPosition, 60));
  EXPECT_EQ(decode_payload(1, std::span(payload).first(7)).error(), DecodeError::wrong_size);
  EXPECT_EQ(decode_payload(1, good).error(), DecodeError::wrong_size);
}

TEST(CodecDecode, RejectsBadHeaderInEveryHeaderByte) {
  for (std::size_t i = 0; i < kBoxHeader.size(); ++i) {
    BoxFrame frame = encode_box_frame(make_write(1, reg::kPosition, 60));
    frame[i] ^= 0x01;
    const auto decoded = decode_box_frame(frame);
    ASSERT_FALSE(decoded.ok()) << to_hex(frame);
    EXPECT_EQ(decoded.error(), DecodeError::bad_header) << to_hex(frame);
  }
}

TEST(CodecDecode, RejectsBadEnd) {
  BoxFrame frame = encode_box_frame(make_write(1, reg::kPosition, 60));
  frame[13] = 0xFA;
  EXPECT_EQ(decode_box_frame(frame).error(), DecodeError::bad_end);
  frame[13] = 0x00;
  EXPECT_EQ(decode_box_frame(frame).error(), DecodeError::bad_end);
}

TEST(CodecDecode, RejectsAccessByteOtherThan0And1) {
  for (const int access : {0x02, 0x10, 0x80, 0xFF}) {
    BoxFrame frame = encode_box_frame(make_write(1, reg::kPosition, 60));
    frame[7] = static_cast<std::uint8_t>(access);
    EXPECT_EQ(decode_box_frame(frame).error(), DecodeError::bad_access) << to_hex(frame);

    Payload payload = encode_payload(make_write(1, reg::kPosition, 60));
    payload[2] = static_cast<std::uint8_t>(access);
    EXPECT_EQ(decode_payload(1, payload).error(), DecodeError::bad_access) << to_hex(payload);
  }
}

TEST(CodecText, ErrorNamesAreDistinct) {
  EXPECT_EQ(to_string(DecodeError::wrong_size), "wrong_size");
  EXPECT_EQ(to_string(DecodeError::bad_header), "bad_header");
  EXPECT_EQ(to_string(DecodeError::bad_end), "bad_end");
  EXPECT_EQ(to_string(DecodeError::bad_access), "bad_access");
}

TEST(CodecText, ToHexIsUppercaseSpaceSeparated) {
  EXPECT_EQ(to_hex(kBoxHeader), "FF FE FD FC");
  const std::uint8_t bytes[] = {0x00, 0x0a, 0xab, 0x10};
  EXPECT_EQ(to_hex(bytes), "00 0A AB 10");
  EXPECT_EQ(to_hex({}), "");
}

TEST(CodecText, DescribeNamesHandAccessRegisterAndValue) {
  EXPECT_EQ(describe(make_write(1, reg::kPosition, 60)), "hand 1 write position(0x0602) = 60");
  EXPECT_EQ(describe(make_read(3, reg::kGripStatus)), "hand 3 read grip_status(0x0F01) = 0");
  EXPECT_EQ(describe(msg(1, reg::kGripStatus, R, 2, 0)),
            "hand 1 read grip_status(0x0F01) = 0 reserve 2");
  EXPECT_EQ(describe(msg(9, Register{0xAB, 0x01}, W, 0, -5)), "hand 9 write unknown(0xAB01) = -5");
}

}  // namespace
}  // namespace dh3::protocol
