#include "dh3/registers.hpp"

#include <cctype>
#include <charconv>
#include <iterator>

#include "dh3/protocol/registers.hpp"

namespace dh3 {

namespace {

// The public header spells each code as a number (its users need no service
// header); the one register map is the protocol layer's, and the build fails
// when the two drift.
static_assert(reg::init_feedback == protocol::reg::kInitFeedback.code());
static_assert(reg::initialize == protocol::reg::kInitialize.code());
static_assert(reg::closing_force == protocol::reg::kClosingForce.code());
static_assert(reg::opening_force == protocol::reg::kOpeningForce.code());
static_assert(reg::position == protocol::reg::kPosition.code());
static_assert(reg::rotation == protocol::reg::kRotation.code());
static_assert(reg::grip_status == protocol::reg::kGripStatus.code());
static_assert(reg::rotation_status == protocol::reg::kRotationStatus.code());
static_assert(reg::can_id == protocol::reg::kCanId.code());
static_assert(reg::firmware_version == protocol::reg::kFirmwareVersion.code());
static_assert(reg::baud_rate == protocol::reg::kBaudRate.code());
static_assert(std::size(protocol::reg::kAll) == 11, "a register added to the map needs its reg:: code here");
}  // namespace

const std::vector<RegisterName>& registers() {
  static const std::vector<RegisterName> all = [] {
    std::vector<RegisterName> names;
    for (const protocol::Register r : protocol::reg::kAll) names.push_back({r.code(), protocol::name(r)});
    return names;
  }();
  return all;
}

std::string_view register_name(std::uint16_t code) {
  for (const auto& r : registers()) {
    if (r.code == code) return r.name;
  }
  return {};
}

std::optional<std::uint16_t> parse_register(std::string_view text) {
  std::string name;
  for (const char c : text) {
    name.push_back(c == '-' ? '_' : static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
  }
  for (const auto& r : registers()) {
    if (r.name == name) return r.code;
  }
  int base = 10;
  std::string_view digits = name;
  if (digits.starts_with("0x")) {
    base = 16;
    digits.remove_prefix(2);
  }
  if (digits.empty()) return std::nullopt;
  unsigned value = 0;
  const auto [end, error] =
      std::from_chars(digits.data(), digits.data() + digits.size(), value, base);
  if (error != std::errc() || end != digits.data() + digits.size() || value > 0xFFFF) {
    return std::nullopt;
  }
  return static_cast<std::uint16_t>(value);
}

std::string firmware_version_text(std::int32_t raw) {
  return protocol::firmware_version_string(raw);
}

}  // namespace dh3
