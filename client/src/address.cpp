#include "dh3/address.hpp"

#include <algorithm>
#include <charconv>

namespace dh3 {
namespace {

bool all_digits(std::string_view text) {
  return !text.empty() &&
         std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; });
}

/// A CAN ID 1-255, nullopt if `text` is not one.
std::optional<std::uint16_t> parse_can_id(std::string_view text) {
  unsigned value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || value < 1 || value > 255) {
    return std::nullopt;
  }
  return static_cast<std::uint16_t>(value);
}

std::vector<std::string_view> split(std::string_view text) {
  std::vector<std::string_view> parts;
  for (;;) {
    const auto slash = text.find('/');
    parts.push_back(text.substr(0, slash));
    if (slash == std::string_view::npos) break;
    text.remove_prefix(slash + 1);
  }
  return parts;
}

Found<HandSpec> bad(std::string_view text, const std::string& why) {
  return {Code::invalid_argument, "bad hand '" + std::string(text) + "': " + why};
}

std::string list(const std::vector<std::string>& items) {
  constexpr std::size_t kShown = 8;
  std::string out;
  for (std::size_t i = 0; i < items.size() && i < kShown; ++i) {
    if (i > 0) out += ", ";
    out += items[i];
  }
  if (items.size() > kShown) out += ", ... (" + std::to_string(items.size()) + " in all)";
  return out;
}

}  // namespace

HandAddress HandSpec::address() const {
  return HandAddress{service.value_or(""), bus.value_or(""), can_id.value_or(0)};
}

bool HandSpec::matches(const HandAddress& hand, std::string_view hand_name) const {
  if (service && *service != hand.service) return false;
  if (bus && *bus != hand.bus) return false;
  if (can_id && *can_id != hand.can_id) return false;
  if (name && *name != hand_name) return false;
  return true;
}

Found<HandSpec> parse_hand_spec(std::string_view text) {
  if (text.empty()) return bad(text, "empty");
  const auto parts = split(text);
  if (parts.size() > 3) return bad(text, "use SERVICE/BUS/ID, BUS/ID, SERVICE/NAME, ID or NAME");
  for (const auto part : parts) {
    if (part.empty()) return bad(text, "an empty part between slashes");
  }
  HandSpec spec;
  spec.text = std::string(text);
  const std::string_view last = parts.back();
  std::optional<std::uint16_t> id;
  if (all_digits(last)) {
    id = parse_can_id(last);
    if (!id) return bad(text, "CAN ID " + std::string(last) + " is out of range (1-255)");
  }
  switch (parts.size()) {
    case 3:
      if (!id) return bad(text, "the last part of SERVICE/BUS/ID must be a CAN ID (1-255)");
      spec.service = std::string(parts[0]);
      spec.bus = std::string(parts[1]);
      spec.can_id = id;
      break;
    case 2:
      if (id) {
        spec.bus = std::string(parts[0]);
        spec.can_id = id;
      } else {
        spec.service = std::string(parts[0]);
        spec.name = std::string(parts[1]);
      }
      break;
    default:
      if (id) {
        spec.can_id = id;
      } else {
        spec.name = std::string(last);
      }
      break;
  }
  return spec;
}

Found<HandAddress> resolve_hand(const HandSpec& spec, const std::vector<KnownHand>& known) {
  if (spec.is_full()) return spec.address();
  std::vector<HandAddress> matching;
  for (const auto& hand : known) {
    if (spec.matches(hand.address, hand.name) &&
        std::find(matching.begin(), matching.end(), hand.address) == matching.end()) {
      matching.push_back(hand.address);
    }
  }
  std::sort(matching.begin(), matching.end());
  if (matching.size() == 1) return matching.front();
  if (matching.empty()) {
    std::vector<std::string> names;
    for (const auto& hand : known) {
      names.push_back(hand.address.to_string() + (hand.name.empty() ? "" : " (" + hand.name + ")"));
    }
    std::sort(names.begin(), names.end());
    return {Code::unknown_hand, "no hand matches '" + spec.text + "'" +
                                    (names.empty() ? std::string(" (no hands known)")
                                                   : " (known: " + list(names) + ")")};
  }
  std::vector<std::string> names;
  for (const auto& address : matching) names.push_back(address.to_string());
  return {Code::invalid_argument, "'" + spec.text + "' is ambiguous: it matches " + list(names) +
                                      "; name the hand as SERVICE/BUS/ID"};
}

}  // namespace dh3
