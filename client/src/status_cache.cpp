// What the client knows: the services, the last status of every hand, and the
// waits on them.

#include <algorithm>

#include "client_core.hpp"
#include "client_endpoints.hpp"
#include "conversions.hpp"

namespace dh3::detail {

void ClientCore::on_status(const std::string& prefix, const msg::HandStatus& sample) {
  statuses_taken_.fetch_add(1, std::memory_order_relaxed);
  if (!followed(sample.service(), sample.bus())) return;
  Actions out;
  {
    std::lock_guard lock(mutex_);
    if (closed_ || !note_participant_locked(prefix, sample.service(), out)) return;
    take_status_locked(prefix, sample);
  }
  run(out);
}

bool ClientCore::take_status_locked(const std::string& prefix, const msg::HandStatus& sample) {
  HandStatus status = to_public(sample);
  const auto origin = status_origins_.find(status.address);
  if (origin != status_origins_.end() && origin->second == prefix) {
    const auto cached = statuses_.find(status.address);
    if (cached != statuses_.end() && status.update_seq <= cached->second.update_seq) return false;
  }
  status_origins_[status.address] = prefix;
  post_status_locked(status);
  statuses_[status.address] = std::move(status);
  changed_.notify_all();
  return true;
}

ServiceInfo ClientCore::info_locked(const std::string& name, const ServiceState& s) const {
  ServiceInfo info = s.info.value_or(ServiceInfo{});
  info.name = name;
  info.ready = ready_locked(name);
  return info;
}

std::vector<ServiceInfo> ClientCore::services() const {
  std::lock_guard lock(mutex_);
  std::vector<ServiceInfo> out;
  for (const auto& [name, state] : services_) out.push_back(info_locked(name, state));
  return out;
}

std::optional<ServiceInfo> ClientCore::service(std::string_view name) const {
  std::lock_guard lock(mutex_);
  const auto it = services_.find(name);
  if (it == services_.end()) return std::nullopt;
  return info_locked(it->first, it->second);
}

std::vector<HandStatus> ClientCore::hands() const {
  std::lock_guard lock(mutex_);
  std::vector<HandStatus> out;
  for (const auto& [address, status] : statuses_) out.push_back(status);
  return out;
}

std::optional<HandStatus> ClientCore::status(const HandAddress& address) const {
  std::lock_guard lock(mutex_);
  const auto it = statuses_.find(address);
  if (it == statuses_.end()) return std::nullopt;
  return it->second;
}

std::vector<KnownHand> ClientCore::known_hands_locked() const {
  std::vector<KnownHand> known;
  for (const auto& [address, status] : statuses_) known.push_back(KnownHand{address, status.name});
  for (const auto& [name, state] : services_) {
    if (!state.info) continue;
    for (const auto& bus : state.info->buses) {
      for (const auto& hand : bus.hands) {
        HandAddress address{name, bus.name, hand.can_id};
        if (statuses_.count(address) == 0) known.push_back(KnownHand{address, hand.name});
      }
    }
  }
  return known;
}

std::vector<KnownHand> ClientCore::known_hands() const {
  std::lock_guard lock(mutex_);
  return known_hands_locked();
}

WatchTraffic ClientCore::watch_traffic() const {
  WatchTraffic traffic;
  traffic.statuses = statuses_taken_.load(std::memory_order_relaxed);
  traffic.events = events_taken_.load(std::memory_order_relaxed);
  traffic.infos = infos_taken_.load(std::memory_order_relaxed);
  if (dds_ != nullptr && dds_->participant != nullptr) {
    traffic.dropped_on_arrival =
        dds_->participant->follow_filter_counts().rejected.load(std::memory_order_relaxed);
  }
  return traffic;
}

Found<ServiceInfo> ClientCore::wait_for_service(std::string_view name, Timeout timeout) {
  std::unique_lock lock(mutex_);
  std::optional<ServiceInfo> found;
  const auto check = [&] {
    if (closed_) return true;
    for (const auto& [service, state] : services_) {
      // Without the info reader no ServiceInfo ever comes: the name is all we know.
      if ((name.empty() || service == name) && (state.info || !has_info_reader_) &&
          ready_locked(service)) {
        found = info_locked(service, state);
        return true;
      }
    }
    return false;
  };
  changed_.wait_for(lock, effective(timeout), check);
  if (found) return *found;
  if (closed_) return {Code::not_connected, error_.empty() ? "the client was closed" : error_};
  const std::string which =
      name.empty() ? "no dh3 service" : "no service '" + std::string(name) + "'";
  return {Code::no_service, which + " found on DDS domain " + std::to_string(options_.domain) +
                                " within " + describe_duration(effective(timeout))};
}

bool ClientCore::wait_for_statuses(Timeout timeout) {
  std::unique_lock lock(mutex_);
  return changed_.wait_for(lock, effective(timeout), [&] {
    if (closed_) return false;
    for (const auto& [name, state] : services_) {
      if (!ready_locked(name)) continue;
      if (!state.info) {
        if (has_info_reader_) return false;
        // No info to list its hands: at least one of them must have reported.
        const bool any = std::any_of(statuses_.begin(), statuses_.end(),
                                     [&](const auto& s) { return s.first.service == name; });
        if (!any) return false;
        continue;
      }
      for (const auto& bus : state.info->buses) {
        if (!followed(name, bus.name)) continue;  // a follower of one bus has no other's
        for (const auto& hand : bus.hands) {
          if (statuses_.count(HandAddress{name, bus.name, hand.can_id}) == 0) return false;
        }
      }
    }
    return true;
  });
}

Found<HandAddress> ClientCore::wait_for_hand(const HandSpec& spec, Timeout timeout) {
  std::unique_lock lock(mutex_);
  std::optional<Found<HandAddress>> answer;
  const auto check = [&] {
    if (closed_) return true;
    auto resolved = resolve_hand(spec, known_hands_locked());
    if (!resolved) {
      // More hands can only make an ambiguous name more ambiguous.
      if (resolved.code() == Code::invalid_argument) {
        answer = std::move(resolved);
        return true;
      }
      return false;
    }
    if (statuses_.count(*resolved) == 0) return false;
    answer = std::move(resolved);
    return true;
  };
  changed_.wait_for(lock, effective(timeout), check);
  if (answer) return std::move(*answer);
  if (closed_) return {Code::not_connected, error_.empty() ? "the client was closed" : error_};
  const std::string within = " within " + describe_duration(effective(timeout));
  if (spec.service) {
    const auto it = services_.find(*spec.service);
    if (it == services_.end() || !it->second.alive) {
      return {Code::no_service, "no service '" + *spec.service + "' found on DDS domain " +
                                    std::to_string(options_.domain) + within};
    }
  } else if (std::none_of(services_.begin(), services_.end(),
                          [](const auto& s) { return s.second.alive; })) {
    return {Code::no_service,
            "no dh3 service found on DDS domain " + std::to_string(options_.domain) + within};
  }
  auto resolved = resolve_hand(spec, known_hands_locked());
  if (!resolved) return resolved;
  return {Code::unknown_hand, "service '" + resolved->service + "' has no hand " + resolved->bus +
                                  "/" + std::to_string(resolved->can_id) + " (no status for it" +
                                  within + ")"};
}

std::optional<HandStatus> ClientCore::wait_status(
    const HandAddress& address, const std::function<bool(const HandStatus&)>& pred,
    Timeout timeout) {
  std::unique_lock lock(mutex_);
  std::optional<HandStatus> found;
  changed_.wait_for(lock, effective(timeout), [&] {
    if (closed_) return true;
    const auto it = statuses_.find(address);
    if (it == statuses_.end() || !pred(it->second)) return false;
    found = it->second;
    return true;
  });
  return found;
}

}  // namespace dh3::detail
