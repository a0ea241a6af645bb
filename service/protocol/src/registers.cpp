#include "dh3/protocol/registers.hpp"

#include <array>
#include <cstddef>

namespace dh3::protocol {

namespace {

struct RegisterInfo {
  Register reg;
  std::string_view name;
  bool writable;
  std::optional<ValueRange> range;
};

// One row per register of the document's command overview. Writable registers
// without a range (0x0801, 0x0802) take a value the hand ignores or interprets
// itself, so the service does not restrict it.
constexpr std::array<RegisterInfo, 11> kRegisterTable{{
    {reg::kInitFeedback, "init_feedback", true, std::nullopt},
    {reg::kInitialize, "initialize", true, std::nullopt},
    {reg::kClosingForce, "closing_force", true, ValueRange{20, 100}},
    {reg::kOpeningForce, "opening_force", true, ValueRange{20, 100}},
    {reg::kPosition, "position", true, ValueRange{0, 100}},
    {reg::kRotation, "rotation", true, ValueRange{0, 100}},
    {reg::kGripStatus, "grip_status", false, std::nullopt},
    {reg::kRotationStatus, "rotation_status", false, std::nullopt},
    {reg::kCanId, "can_id", true, ValueRange{1, 255}},
    {reg::kFirmwareVersion, "firmware_version", false, std::nullopt},
    {reg::kBaudRate, "baud_rate", true, ValueRange{0, 5}},
}};

static_assert(std::size(reg::kAll) == kRegisterTable.size(),
              "every register of reg::kAll needs a row in the table");

const RegisterInfo* find_info(Register r) {
  for (const RegisterInfo& info : kRegisterTable) {
    if (info.reg == r) return &info;
  }
  return nullptr;
}

// Index = value of register 0x1401 (spec: "CAN baud rate").
constexpr std::array<std::uint32_t, 6> kBaudRates{500'000, 400'000, 250'000,
                                                  200'000, 125'000, 100'000};

}  // namespace

std::string_view to_string(RegisterError error) {
  switch (error) {
    case RegisterError::unknown_register:
      return "unknown_register";
    case RegisterError::read_only:
      return "read_only";
    case RegisterError::out_of_range:
      return "out_of_range";
  }
  return "invalid RegisterError";
}

bool is_known(Register r) {
  return find_info(r) != nullptr;
}

bool is_writable(Register r) {
  const RegisterInfo* info = find_info(r);
  return info != nullptr && info->writable;
}

std::optional<ValueRange> write_range(Register r) {
  const RegisterInfo* info = find_info(r);
  if (info == nullptr || !info->writable) return std::nullopt;
  return info->range;
}

Result<void, RegisterError> check_write(Register r, std::int32_t value) {
  const RegisterInfo* info = find_info(r);
  if (info == nullptr) return fail(RegisterError::unknown_register);
  if (!info->writable) return fail(RegisterError::read_only);
  if (info->range && !info->range->contains(value)) return fail(RegisterError::out_of_range);
  return {};
}

std::string_view name(Register r) {
  const RegisterInfo* info = find_info(r);
  return info != nullptr ? info->name : std::string_view{"unknown"};
}

std::optional<std::uint32_t> baud_index_to_bps(std::int32_t index) {
  if (index < 0 || static_cast<std::size_t>(index) >= kBaudRates.size()) return std::nullopt;
  return kBaudRates[static_cast<std::size_t>(index)];
}

std::string firmware_version_string(std::int32_t raw) {
  const auto bits = static_cast<std::uint32_t>(raw);
  std::string text;
  for (int shift = 24; shift >= 0; shift -= 8) {
    if (!text.empty()) text += '.';
    text += std::to_string((bits >> shift) & 0xFFU);
  }
  return text;
}

}  // namespace dh3::protocol
