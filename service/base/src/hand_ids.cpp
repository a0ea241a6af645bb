#include "dh3/base/hand_ids.hpp"

#include <array>
#include <charconv>
#include <optional>
#include <utility>

namespace dh3 {

namespace {

/// "A-B" with both numbers; nullopt for anything else (then read as one ID).
std::optional<std::pair<std::string_view, std::string_view>> range_of(std::string_view item) {
  const auto dash = item.find('-');
  if (dash == std::string_view::npos || dash == 0 || dash + 1 == item.size()) return std::nullopt;
  return std::pair{item.substr(0, dash), item.substr(dash + 1)};
}

}  // namespace

Result<std::uint8_t, std::string> parse_hand_id(std::string_view text) {
  unsigned id = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), id);
  const bool digits_only =
      !text.empty() && text.find_first_not_of("0123456789") == std::string_view::npos;
  if (!digits_only || error == std::errc::invalid_argument || end != text.data() + text.size()) {
    return fail("hand id '" + std::string(text) + "' is not a number");
  }
  if (error == std::errc::result_out_of_range || id > 255) {
    return fail("hand id " + std::string(text) + " is out of range 1-255");
  }
  if (id == 0) {
    return fail("hand id 0 is not a hand's id (ID 0 addresses whichever hand is there); use 1-255");
  }
  return static_cast<std::uint8_t>(id);
}

Result<std::vector<std::uint8_t>, std::string> parse_hand_ids(std::string_view text) {
  if (text.empty()) return fail("no hand ids");
  std::vector<std::uint8_t> ids;
  std::array<bool, 256> seen{};
  const auto add = [&](std::uint8_t id) -> Result<void, std::string> {
    if (seen[id]) return fail("hand id " + std::to_string(id) + " is listed twice");
    seen[id] = true;
    ids.push_back(id);
    return {};
  };
  while (true) {
    const auto comma = text.find(',');
    const std::string_view item = text.substr(0, comma);
    if (const auto range = range_of(item)) {
      auto first = parse_hand_id(range->first);
      if (!first) return fail(std::move(first).error());
      auto last = parse_hand_id(range->second);
      if (!last) return fail(std::move(last).error());
      if (*last < *first) return fail("empty range " + std::string(item));
      for (unsigned id = *first; id <= *last; ++id) {
        if (auto added = add(static_cast<std::uint8_t>(id)); !added) {
          return fail(std::move(added).error());
        }
      }
    } else {
      auto id = parse_hand_id(item);
      if (!id) return fail(std::move(id).error());
      if (auto added = add(*id); !added) return fail(std::move(added).error());
    }
    if (comma == std::string_view::npos) break;
    text.remove_prefix(comma + 1);
  }
  return ids;
}

}  // namespace dh3
