#include "dds/hand_directory.hpp"

namespace dh3::dds {

std::uint16_t HandDirectory::add_bus(std::string name, const std::vector<Hand>& hands) {
  auto bus = std::make_unique<Bus>();
  bus->name = std::move(name);
  for (const Hand& hand : hands) {
    bus->known[hand.can_id].store(true);
    bus->names[hand.can_id] = hand.name;
  }
  buses_.push_back(std::move(bus));
  return static_cast<std::uint16_t>(buses_.size() - 1);
}

std::optional<std::uint16_t> HandDirectory::find_bus(std::string_view name) const {
  for (std::size_t i = 0; i < buses_.size(); ++i) {
    if (buses_[i]->name == name) return static_cast<std::uint16_t>(i);
  }
  return std::nullopt;
}

std::string HandDirectory::bus_names() const {
  std::string names;
  for (const auto& bus : buses_) {
    if (!names.empty()) names += ", ";
    names += bus->name;
  }
  return names;
}

bool HandDirectory::add_hand(std::uint16_t bus, std::uint8_t can_id) {
  return !buses_[bus]->known[can_id].exchange(true, std::memory_order_acq_rel);
}

std::string HandDirectory::hand_name(std::uint16_t bus, std::uint8_t can_id) const {
  return buses_[bus]->names[can_id];
}

std::vector<HandDirectory::Hand> HandDirectory::hands(std::uint16_t bus) const {
  std::vector<Hand> out;
  const Bus& b = *buses_[bus];
  for (std::size_t id = 1; id < b.known.size(); ++id) {
    if (b.known[id].load(std::memory_order_acquire)) {
      out.push_back({static_cast<std::uint8_t>(id), b.names[id]});
    }
  }
  return out;
}

}  // namespace dh3::dds
