#pragma once
// Which buses a service has, by name, and for each the roster of its hands
// (hand/hand_roster.hpp): the directory keeps no list of hands of its own, it
// asks the bus's roster, which the bus's scheduler owns. Requests are checked
// against it before anything is queued; hand lookups are lock-free, so the
// request path never waits for a bus thread that reports a new hand.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dh3/hand/hand_roster.hpp"

namespace dh3::dds {

class HandDirectory {
 public:
  using Hand = hand::HandConfig;

  /// Adds a bus whose hands `roster` knows (it must outlive the directory);
  /// returns the bus's index.
  std::uint16_t add_bus(std::string name, const hand::HandRoster& roster);

  [[nodiscard]] std::size_t bus_count() const { return buses_.size(); }
  [[nodiscard]] const std::string& bus_name(std::uint16_t bus) const { return buses_[bus].name; }
  /// The bus's index, nullopt if the service has no bus of that name.
  [[nodiscard]] std::optional<std::uint16_t> find_bus(std::string_view name) const;
  /// "bus0, bus1" for messages that list what exists.
  [[nodiscard]] std::string bus_names() const;

  [[nodiscard]] bool has_hand(std::uint16_t bus, std::uint8_t can_id) const {
    return buses_[bus].roster->knows(can_id);
  }
  /// The hand's configured name, empty if none.
  [[nodiscard]] std::string hand_name(std::uint16_t bus, std::uint8_t can_id) const {
    return buses_[bus].roster->name(can_id);
  }
  /// Every known hand of a bus, by CAN ID.
  [[nodiscard]] std::vector<Hand> hands(std::uint16_t bus) const {
    return buses_[bus].roster->hands();
  }

 private:
  struct Bus {
    std::string name;
    const hand::HandRoster* roster = nullptr;
  };
  std::vector<Bus> buses_;  ///< fixed after start-up
};

}  // namespace dh3::dds
