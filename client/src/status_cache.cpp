// StatusCache: the newest status of every hand, in the order its service sent them.

#include "status_cache.hpp"

#include <algorithm>

namespace dh3::detail {

bool StatusCache::take(const std::string& incarnation, const HandStatus& status) {
  const auto origin = origins_.find(status.address);
  if (origin != origins_.end() && origin->second == incarnation) {
    const auto cached = statuses_.find(status.address);
    // A hand marked lost with its service takes the same sample again: the
    // service was frozen or cut off and its refresh says it is back.
    if (cached != statuses_.end() && !cached->second.service_lost &&
        status.update_seq <= cached->second.update_seq) {
      return false;
    }
  }
  origins_[status.address] = incarnation;
  statuses_[status.address] = status;
  return true;
}

std::vector<HandStatus> StatusCache::mark_lost(const std::string& service) {
  std::vector<HandStatus> changed;
  for (auto& [address, status] : statuses_) {
    if (address.service != service || !status.online) continue;
    status.online = false;
    status.service_lost = true;
    changed.push_back(status);
  }
  return changed;
}

std::vector<HandStatus> StatusCache::mark_regained(const std::string& incarnation) {
  std::vector<HandStatus> changed;
  if (incarnation.empty()) return changed;
  for (auto& [address, status] : statuses_) {
    const auto origin = origins_.find(address);
    if (!status.service_lost || origin == origins_.end() || origin->second != incarnation) continue;
    status.online = true;
    status.service_lost = false;
    changed.push_back(status);
  }
  return changed;
}

std::optional<HandStatus> StatusCache::find(const HandAddress& address) const {
  const auto it = statuses_.find(address);
  if (it == statuses_.end()) return std::nullopt;
  return it->second;
}

bool StatusCache::has(const HandAddress& address) const {
  return statuses_.count(address) > 0;
}

bool StatusCache::has_service(const std::string& service) const {
  return std::any_of(statuses_.begin(), statuses_.end(),
                     [&](const auto& s) { return s.first.service == service; });
}

std::vector<HandStatus> StatusCache::all() const {
  return matching(std::nullopt);
}

std::vector<HandStatus> StatusCache::of_service(const std::string& service) const {
  std::vector<HandStatus> out;
  for (const auto& [address, status] : statuses_) {
    if (address.service == service) out.push_back(status);
  }
  return out;
}

std::vector<HandStatus> StatusCache::matching(const std::optional<HandAddress>& only) const {
  std::vector<HandStatus> out;
  for (const auto& [address, status] : statuses_) {
    if (!only || *only == address) out.push_back(status);
  }
  return out;
}

std::vector<KnownHand> StatusCache::known_hands(const std::vector<ServiceInfo>& infos) const {
  std::vector<KnownHand> known;
  for (const auto& [address, status] : statuses_) known.push_back(KnownHand{address, status.name});
  for (const auto& info : infos) {
    for (const auto& bus : info.buses) {
      for (const auto& hand : bus.hands) {
        HandAddress address{info.name, bus.name, hand.can_id};
        if (statuses_.count(address) == 0) known.push_back(KnownHand{address, hand.name});
      }
    }
  }
  return known;
}

}  // namespace dh3::detail
