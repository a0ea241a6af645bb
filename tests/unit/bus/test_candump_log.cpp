// The candump log lines the flight recorder writes and the replay reads.
// can-utils' own readers are run on a real recording in
// tests/integration/service/test_service_recording.cpp.

#include <gtest/gtest.h>

#include "dh3/bus/candump_log.hpp"

namespace dh3::bus {
namespace {

using namespace std::chrono_literals;

WallTime at(std::int64_t micros) { return WallTime(std::chrono::microseconds(micros)); }

TEST(CandumpLog, SentFrameIsWrittenWithItsTimeAndT) {
  const LoggedFrame frame{at(1'700'000'000'123'456), FrameDirection::sent,
                          CanFrame{0x01, 8, {0x06, 0x02, 0x01, 0x00, 0x3C, 0x00, 0x00, 0x00}}};
  EXPECT_EQ(format_log_line(frame, "bus0"), "(1700000000.123456) bus0 001#060201003C000000 T\n");
}

TEST(CandumpLog, ReceivedFrameIsWrittenWithR) {
  const LoggedFrame frame{at(1'700'000'001'000'007), FrameDirection::received,
                          CanFrame{0x0FF, 8, {0x0F, 0x01, 0, 0, 0x03, 0, 0, 0}}};
  EXPECT_EQ(format_log_line(frame, "can0"), "(1700000001.000007) can0 0FF#0F01000003000000 R\n");
}

TEST(CandumpLog, TimeIsCutToTheMicrosecondAndPaddedLikeCandump) {
  const LoggedFrame frame{WallTime(std::chrono::nanoseconds(5'000'000'999)),
                          FrameDirection::sent, CanFrame{0x7FF, 2, {0xAB, 0xCD}}};
  EXPECT_EQ(format_log_line(frame, "x"), "(0000000005.000000) x 7FF#ABCD T\n");
}

TEST(CandumpLog, ShortFramesHaveOnlyTheirBytes) {
  const LoggedFrame frame{at(0), FrameDirection::received, CanFrame{0x12, 0, {}}};
  EXPECT_EQ(format_log_line(frame, "b"), "(0000000000.000000) b 012# R\n");
}

TEST(CandumpLog, DeviceNamesLoseWhatWouldSplitTheLine) {
  EXPECT_EQ(log_device_name("left hand/bus"), "left_hand_bus");
  EXPECT_EQ(log_device_name("bus-0.a_b"), "bus-0.a_b");
  EXPECT_EQ(log_device_name(""), "bus");
}

TEST(CandumpLog, ALineReadsBackAsWritten) {
  for (const auto direction : {FrameDirection::sent, FrameDirection::received}) {
    const LoggedFrame frame{at(1'700'000'000'654'321), direction,
                            CanFrame{0x03, 8, {0x0F, 0x02, 0, 0, 0x02, 0, 0, 0}}};
    const auto line = parse_log_line(format_log_line(frame, "bus1"));
    ASSERT_TRUE(line) << to_string(line.error());
    EXPECT_EQ(line->time, frame.time);
    EXPECT_EQ(line->device, "bus1");
    EXPECT_EQ(line->frame, frame.frame);
    EXPECT_EQ(line->direction, direction);
  }
}

TEST(CandumpLog, CandumpsPlainLinesHaveNoDirection) {
  const auto line = parse_log_line("(1700000000.000100) vcan0 002#0602010028000000");
  ASSERT_TRUE(line);
  EXPECT_EQ(line->time, at(1'700'000'000'000'100));
  EXPECT_EQ(line->device, "vcan0");
  EXPECT_EQ(line->frame, (CanFrame{2, 8, {0x06, 0x02, 0x01, 0x00, 0x28, 0, 0, 0}}));
  EXPECT_FALSE(line->direction.has_value());
}

TEST(CandumpLog, NanosecondTimesAndLowerCaseHexAreRead) {
  const auto line = parse_log_line("(1.000000500) c 0ab#ff");
  ASSERT_TRUE(line);
  EXPECT_EQ(line->time, WallTime(std::chrono::nanoseconds(1'000'000'500)));
  EXPECT_EQ(line->frame, (CanFrame{0xAB, 1, {0xFF}}));
}

TEST(CandumpLog, CommentsAndDropNotesAreNoFrames) {
  for (const char* text : {"", "# comment", "DROPCOUNT: dropped 3 CAN frames on 'can0' socket"}) {
    const auto line = parse_log_line(text);
    ASSERT_FALSE(line) << text;
    EXPECT_EQ(line.error(), LogLineError::not_a_frame) << text;
  }
}

TEST(CandumpLog, FramesHandsNeverSendAreUnsupported) {
  for (const char* text : {"(1.000000) c 12345678#00", "(1.000000) c 123#R",
                           "(1.000000) c 123##1AABB"}) {
    const auto line = parse_log_line(text);
    ASSERT_FALSE(line) << text;
    EXPECT_EQ(line.error(), LogLineError::unsupported) << text;
  }
}

TEST(CandumpLog, BrokenLinesAreMalformed) {
  for (const char* text : {"(1.000000 c 123#00", "(x.000000) c 123#00", "(1.000000) c",
                           "(1.000000) c 1G3#00", "(1.000000) c 123#0", "(1.000000) c 12#00",
                           "(1.000000) c 123#000102030405060708", "(1.) c 123#00"}) {
    const auto line = parse_log_line(text);
    ASSERT_FALSE(line) << text;
    EXPECT_EQ(line.error(), LogLineError::malformed) << text;
  }
}

}  // namespace
}  // namespace dh3::bus
