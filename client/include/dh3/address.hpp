#pragma once
// How a user names a hand: "service/bus/id" (always unambiguous), "bus/id",
// "service/name", a bare CAN ID or a bare name. The short forms resolve against
// the hands the client knows and must match exactly one.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dh3/export.hpp"
#include "dh3/types.hpp"

namespace dh3 {

/// A parsed hand reference; the parts the user left out are empty.
struct HandSpec {
  std::optional<std::string> service;
  std::optional<std::string> bus;
  std::optional<std::uint16_t> can_id;
  std::optional<std::string> name;
  std::string text;  ///< as the user wrote it, for messages

  /// True for "service/bus/id": it needs no lookup.
  [[nodiscard]] bool is_full() const { return service && bus && can_id; }
  /// The address of a full spec.
  [[nodiscard]] DH3_CLIENT_API HandAddress address() const;
  /// True if `hand` (and its configured `hand_name`) fits this spec.
  [[nodiscard]] DH3_CLIENT_API bool matches(const HandAddress& hand,
                                            std::string_view hand_name) const;
};

/// Parses a hand reference:
///   "cell/bus0/2"  service cell, bus bus0, CAN ID 2
///   "bus0/2"       bus bus0, CAN ID 2, any service
///   "cell/left"    the hand named "left" of service cell
///   "2"            CAN ID 2 on any bus of any service
///   "left"         the hand named "left"
/// CAN IDs are 1-255. Fails with INVALID_ARGUMENT and a message otherwise.
[[nodiscard]] DH3_CLIENT_API Found<HandSpec> parse_hand_spec(std::string_view text);

/// A hand the client knows of, for resolving short forms.
struct KnownHand {
  HandAddress address;
  std::string name;
};

/// The one known hand that `spec` names. A full spec resolves to itself even
/// if unknown (the service will say whether it exists). Fails with
/// UNKNOWN_HAND when nothing matches and INVALID_ARGUMENT when several do,
/// listing them.
[[nodiscard]] DH3_CLIENT_API Found<HandAddress> resolve_hand(const HandSpec& spec,
                                                             const std::vector<KnownHand>& known);

}  // namespace dh3
