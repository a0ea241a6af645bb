// Register map tests: names, writability, the document's ranges (rejected, never
// clamped), baud indices and the firmware version reading.

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <optional>
#include <set>
#include <string>

#include "dh3/protocol/registers.hpp"

namespace dh3::protocol {
namespace {

constexpr Register kUnknown{0x06, 0x01};  // function known, sub-function not

TEST(Registers, CodesMatchTheDocument) {
  EXPECT_EQ(reg::kInitFeedback.code(), 0x0801);
  EXPECT_EQ(reg::kInitialize.code(), 0x0802);
  EXPECT_EQ(reg::kClosingForce.code(), 0x0502);
  EXPECT_EQ(reg::kOpeningForce.code(), 0x0503);
  EXPECT_EQ(reg::kPosition.code(), 0x0602);
  EXPECT_EQ(reg::kRotation.code(), 0x0702);
  EXPECT_EQ(reg::kGripStatus.code(), 0x0F01);
  EXPECT_EQ(reg::kRotationStatus.code(), 0x0F02);
  EXPECT_EQ(reg::kCanId.code(), 0x1201);
  EXPECT_EQ(reg::kFirmwareVersion.code(), 0x1301);
  EXPECT_EQ(reg::kBaudRate.code(), 0x1401);
  EXPECT_EQ(Register::from_code(0x0602), reg::kPosition);
  EXPECT_EQ(Register::from_code(0x1401), reg::kBaudRate);
}

TEST(Registers, EveryRegisterIsKnownWithADistinctName) {
  std::set<std::string> names;
  for (const Register r : reg::kAll) {
    EXPECT_TRUE(is_known(r)) << r.code();
    const std::string n(name(r));
    EXPECT_NE(n, "unknown") << r.code();
    EXPECT_FALSE(n.empty()) << r.code();
    names.insert(n);
  }
  EXPECT_EQ(names.size(), std::size(reg::kAll));
  EXPECT_EQ(name(reg::kPosition), "position");
  EXPECT_EQ(name(reg::kGripStatus), "grip_status");
}

TEST(Registers, UnknownRegistersAreNotKnown) {
  for (const Register r : {kUnknown, Register{0x00, 0x00}, Register{0x05, 0x01},
                           Register{0x0F, 0x03}, Register{0x13, 0x02}, Register{0xFF, 0xFF}}) {
    EXPECT_FALSE(is_known(r)) << r.code();
    EXPECT_FALSE(is_writable(r)) << r.code();
    EXPECT_EQ(name(r), "unknown") << r.code();
    EXPECT_FALSE(write_range(r).has_value()) << r.code();
  }
}

TEST(Registers, StatusAndVersionAreReadOnly) {
  for (const Register r : {reg::kGripStatus, reg::kRotationStatus, reg::kFirmwareVersion}) {
    EXPECT_FALSE(is_writable(r)) << r.code();
    EXPECT_FALSE(write_range(r).has_value()) << r.code();
    EXPECT_EQ(check_write(r, 0).error(), RegisterError::read_only) << r.code();
    EXPECT_EQ(check_write(r, 2).error(), RegisterError::read_only) << r.code();
  }
}

TEST(Registers, EveryOtherRegisterIsWritable) {
  for (const Register r :
       {reg::kInitFeedback, reg::kInitialize, reg::kClosingForce, reg::kOpeningForce,
        reg::kPosition, reg::kRotation, reg::kCanId, reg::kBaudRate}) {
    EXPECT_TRUE(is_writable(r)) << r.code();
  }
}

TEST(Registers, WriteRangesFollowTheDocument) {
  const auto expect_range = [](Register r, std::int32_t min, std::int32_t max) {
    const std::optional<ValueRange> range = write_range(r);
    ASSERT_TRUE(range.has_value()) << r.code();
    EXPECT_EQ(range->min, min) << r.code();
    EXPECT_EQ(range->max, max) << r.code();
  };
  expect_range(reg::kClosingForce, 20, 100);
  expect_range(reg::kOpeningForce, 20, 100);
  expect_range(reg::kPosition, 0, 100);
  expect_range(reg::kRotation, 0, 100);
  expect_range(reg::kCanId, 1, 255);
  expect_range(reg::kBaudRate, 0, 5);
  EXPECT_FALSE(write_range(reg::kInitFeedback).has_value());
  EXPECT_FALSE(write_range(reg::kInitialize).has_value());
}

struct Boundary {
  Register reg;
  std::int32_t below;  // rejected
  std::int32_t min;    // accepted
  std::int32_t max;    // accepted
  std::int32_t above;  // rejected
};

TEST(CheckWrite, BoundariesAreRejectedNotClamped) {
  const Boundary boundaries[] = {
      {reg::kClosingForce, 19, 20, 100, 101}, {reg::kOpeningForce, 19, 20, 100, 101},
      {reg::kPosition, -1, 0, 100, 101},      {reg::kRotation, -1, 0, 100, 101},
      {reg::kCanId, 0, 1, 255, 256},          {reg::kBaudRate, -1, 0, 5, 6},
  };
  for (const Boundary& b : boundaries) {
    SCOPED_TRACE(std::string(name(b.reg)));
    EXPECT_EQ(check_write(b.reg, b.below).error(), RegisterError::out_of_range);
    EXPECT_TRUE(check_write(b.reg, b.min).ok());
    EXPECT_TRUE(check_write(b.reg, (b.min + b.max) / 2).ok());
    EXPECT_TRUE(check_write(b.reg, b.max).ok());
    EXPECT_EQ(check_write(b.reg, b.above).error(), RegisterError::out_of_range);
    EXPECT_EQ(check_write(b.reg, std::numeric_limits<std::int32_t>::min()).error(),
              RegisterError::out_of_range);
    EXPECT_EQ(check_write(b.reg, std::numeric_limits<std::int32_t>::max()).error(),
              RegisterError::out_of_range);
    // A value that is in range only after 16-bit truncation is still rejected.
    EXPECT_EQ(check_write(b.reg, 65536 + b.min).error(), RegisterError::out_of_range);
  }
}

TEST(CheckWrite, InitRegistersTakeAnyValue) {
  for (const Register r : {reg::kInitFeedback, reg::kInitialize}) {
    for (const std::int32_t v :
         {0, 1, kInitFeedbackEnabled, -1, std::numeric_limits<std::int32_t>::max()}) {
      EXPECT_TRUE(check_write(r, v).ok()) << r.code() << " " << v;
    }
  }
}

TEST(CheckWrite, UnknownRegisterIsRejected) {
  EXPECT_EQ(check_write(kUnknown, 50).error(), RegisterError::unknown_register);
  EXPECT_EQ(check_write(Register{0x99, 0x01}, 0).error(), RegisterError::unknown_register);
}

TEST(CheckWrite, ErrorNames) {
  EXPECT_EQ(to_string(RegisterError::unknown_register), "unknown_register");
  EXPECT_EQ(to_string(RegisterError::read_only), "read_only");
  EXPECT_EQ(to_string(RegisterError::out_of_range), "out_of_range");
}

TEST(BaudRate, IndexToBitsPerSecondFollowsTheTable) {
  EXPECT_EQ(baud_index_to_bps(0), 500'000u);
  EXPECT_EQ(baud_index_to_bps(1), 400'000u);
  EXPECT_EQ(baud_index_to_bps(2), 250'000u);
  EXPECT_EQ(baud_index_to_bps(3), 200'000u);
  EXPECT_EQ(baud_index_to_bps(4), 125'000u);
  EXPECT_EQ(baud_index_to_bps(5), 100'000u);
  EXPECT_EQ(baud_index_to_bps(-1), std::nullopt);
  EXPECT_EQ(baud_index_to_bps(6), std::nullopt);
  EXPECT_EQ(baud_index_to_bps(std::numeric_limits<std::int32_t>::min()), std::nullopt);
}

TEST(FirmwareVersion, DocumentExampleReads4120) {
  // Data bytes 00 02 01 04 on the wire = little-endian 0x04010200 (reading 7).
  EXPECT_EQ(firmware_version_string(0x04010200), "4.1.2.0");
}

TEST(FirmwareVersion, BytesHighToLowAllUnsigned) {
  EXPECT_EQ(firmware_version_string(0), "0.0.0.0");
  EXPECT_EQ(firmware_version_string(0x01020304), "1.2.3.4");
  EXPECT_EQ(firmware_version_string(-1), "255.255.255.255");
  EXPECT_EQ(firmware_version_string(std::numeric_limits<std::int32_t>::min()), "128.0.0.0");
}

}  // namespace
}  // namespace dh3::protocol
