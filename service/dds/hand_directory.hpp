#pragma once
// Which buses a service has and which hands are known on each: the hands its
// config names, plus those a bus discovered since. Requests are checked against
// it before anything is queued. Reads are lock-free (one flag per CAN ID), so
// the request path never waits for a bus thread that reports a new hand.

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace dh3::dds {

class HandDirectory {
 public:
  struct Hand {
    std::uint8_t can_id = 0;
    std::string name;
  };

  /// Adds a bus with its configured hands; returns its index.
  std::uint16_t add_bus(std::string name, const std::vector<Hand>& hands);

  [[nodiscard]] std::size_t bus_count() const { return buses_.size(); }
  [[nodiscard]] const std::string& bus_name(std::uint16_t bus) const { return buses_[bus]->name; }
  /// The bus's index, nullopt if the service has no bus of that name.
  [[nodiscard]] std::optional<std::uint16_t> find_bus(std::string_view name) const;
  /// "bus0, bus1" for messages that list what exists.
  [[nodiscard]] std::string bus_names() const;

  [[nodiscard]] bool has_hand(std::uint16_t bus, std::uint8_t can_id) const {
    return buses_[bus]->known[can_id].load(std::memory_order_acquire);
  }
  /// Records a hand the bus reported; true if it was not known before.
  bool add_hand(std::uint16_t bus, std::uint8_t can_id);
  /// The hand's configured name, empty if none.
  [[nodiscard]] std::string hand_name(std::uint16_t bus, std::uint8_t can_id) const;
  /// Every known hand of a bus, by CAN ID.
  [[nodiscard]] std::vector<Hand> hands(std::uint16_t bus) const;

 private:
  struct Bus {
    std::string name;
    std::array<std::atomic<bool>, 256> known{};
    std::array<std::string, 256> names{};  ///< from config; fixed after add_bus()
  };
  std::vector<std::unique_ptr<Bus>> buses_;  ///< fixed after start-up
};

}  // namespace dh3::dds
