#include "dh3/registers.hpp"

#include <cctype>
#include <charconv>

namespace dh3 {

const std::vector<RegisterName>& registers() {
  static const std::vector<RegisterName> all = {
      {reg::init_feedback, "init_feedback"},
      {reg::initialize, "initialize"},
      {reg::closing_force, "closing_force"},
      {reg::opening_force, "opening_force"},
      {reg::position, "position"},
      {reg::rotation, "rotation"},
      {reg::grip_status, "grip_status"},
      {reg::rotation_status, "rotation_status"},
      {reg::can_id, "can_id"},
      {reg::firmware_version, "firmware_version"},
      {reg::baud_rate, "baud_rate"},
  };
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
  const auto bits = static_cast<std::uint32_t>(raw);
  std::string text;
  for (int shift = 24; shift >= 0; shift -= 8) {
    if (!text.empty()) text.push_back('.');
    text += std::to_string((bits >> shift) & 0xFFU);
  }
  return text;
}

}  // namespace dh3
