#include "hand_directory.hpp"

namespace dh3::dds {

std::uint16_t HandDirectory::add_bus(std::string name, const hand::HandRoster& roster) {
  buses_.push_back(Bus{std::move(name), &roster});
  return static_cast<std::uint16_t>(buses_.size() - 1);
}

std::optional<std::uint16_t> HandDirectory::find_bus(std::string_view name) const {
  for (std::size_t i = 0; i < buses_.size(); ++i) {
    if (buses_[i].name == name) return static_cast<std::uint16_t>(i);
  }
  return std::nullopt;
}

std::string HandDirectory::bus_names() const {
  std::string names;
  for (const auto& bus : buses_) {
    if (!names.empty()) names += ", ";
    names += bus.name;
  }
  return names;
}

}  // namespace dh3::dds
