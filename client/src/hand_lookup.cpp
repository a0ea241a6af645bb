#include "hand_lookup.hpp"

#include <algorithm>

#include "conversions.hpp"

namespace dh3::detail {
namespace {

/// "dh3/bus0/1 (left), dh3/bus0/2": what the user could have named instead.
std::string listed_hands(const std::vector<const ServiceInfo*>& services) {
  std::string text;
  for (const auto* service : services) {
    for (const auto& bus : service->buses) {
      for (const auto& hand : bus.hands) {
        if (!text.empty()) text += ", ";
        text += HandAddress{service->name, bus.name, hand.can_id}.to_string();
        if (!hand.name.empty()) text += " (" + hand.name + ")";
      }
    }
  }
  return text.empty() ? "no hands" : text;
}

}  // namespace

std::optional<std::string> hand_ruled_out(const HandSpec& spec,
                                          const std::vector<ServiceInfo>& infos) {
  std::vector<const ServiceInfo*> candidates;
  for (const auto& info : infos) {
    if (!spec.service || info.name == *spec.service) candidates.push_back(&info);
  }
  if (candidates.empty()) return std::nullopt;
  for (const auto* service : candidates) {
    for (const auto& bus : service->buses) {
      if (spec.bus && bus.name != *spec.bus) continue;
      if (bus.hands.empty()) return std::nullopt;  // a discovering bus may still find it
      const bool fits = std::any_of(bus.hands.begin(), bus.hands.end(), [&](const HandInfo& hand) {
        return spec.matches(HandAddress{service->name, bus.name, hand.can_id}, hand.name);
      });
      if (fits) return std::nullopt;
    }
  }
  const std::string listed = " (" + listed_hands(candidates) + " listed)";
  if (spec.is_full()) {
    return "service '" + *spec.service + "' has no hand " + *spec.bus + "/" +
           std::to_string(*spec.can_id) + listed;
  }
  return "no hand matches '" + spec.text + "'" + listed;
}

std::string no_status_for(const HandAddress& hand, std::chrono::milliseconds waited) {
  return "service '" + hand.service + "' has no hand " + hand.bus + "/" +
         std::to_string(hand.can_id) + " (no status for it within " + describe_duration(waited) +
         ")";
}

std::string no_service_found(std::string_view name, int domain, std::chrono::milliseconds waited,
                             const std::string& seen) {
  const std::string which =
      name.empty() ? "no dh3 service" : "no service '" + std::string(name) + "'";
  return which + " found on DDS domain " + std::to_string(domain) + " within " +
         describe_duration(waited) + (seen.empty() ? "" : "; " + seen);
}

}  // namespace dh3::detail
