// ServiceTracker: services' incarnations, their readiness, restarts and losses.

#include "service_tracker.hpp"

namespace dh3::detail {

bool ServiceTracker::note_participant(const std::string& prefix, const std::string& service,
                                      Outcome& out) {
  if (service.empty() || participant_gone(prefix)) return false;
  auto& participant = participants_[prefix];
  participant.service = service;
  participant.alive = true;
  const auto& state = services_[service];
  if (state.incarnation.empty() || !state.alive) make_current(service, prefix, out);
  return true;
}

void ServiceTracker::make_current(const std::string& service, const std::string& prefix,
                                  Outcome& out) {
  auto& state = services_[service];
  if (state.incarnation != prefix) {
    state.incarnation = prefix;
    // The info of another incarnation is not this one's.
    state.info.reset();
  }
  state.alive = true;
  out.service = service;
  out.may_dispatch = true;
}

void ServiceTracker::lose(const std::string& service, const std::string& why, Outcome& out) {
  auto& state = services_[service];
  state.alive = false;
  if (auto it = participants_.find(state.incarnation); it != participants_.end()) {
    it->second.alive = false;
  }
  out.service = service;
  out.lost = state.incarnation;
  out.why = why;
  out.lost_service = true;
}

ServiceTracker::Outcome ServiceTracker::participant_left(const std::string& prefix) {
  Outcome out;
  request_readers_.erase(prefix);
  reply_writers_.erase(prefix);
  event_writers_.erase(prefix);
  const auto it = participants_.find(prefix);
  if (it == participants_.end() || !it->second.alive) return out;
  it->second.alive = false;
  const std::string service = it->second.service;
  const auto state = services_.find(service);
  if (state == services_.end() || state->second.incarnation != prefix || !state->second.alive) {
    return out;
  }
  lose(service, "service '" + service + "' left the domain", out);
  // Another live participant of that name (a newer instance that was not yet
  // current) takes over; the latest started first.
  const Participant* best = nullptr;
  std::string best_prefix;
  for (const auto& [other, p] : participants_) {
    if (!p.alive || p.service != service) continue;
    if (best == nullptr || (p.has_info && (!best->has_info || p.started_ns > best->started_ns))) {
      best = &p;
      best_prefix = other;
    }
  }
  if (best != nullptr) make_current(service, best_prefix, out);
  return out;
}

bool ServiceTracker::take_info(const std::string& prefix, ServiceInfo info, Outcome& out) {
  const std::string service = info.name;
  if (!note_participant(prefix, service, out)) return false;
  auto& participant = participants_[prefix];
  participant.has_info = true;
  participant.started_ns = info.started_ns;
  auto& state = services_[service];
  if (state.incarnation != prefix) {
    const auto current = participants_.find(state.incarnation);
    const bool newer = current == participants_.end() || !current->second.has_info ||
                       info.started_ns > current->second.started_ns;
    if (!newer) return false;  // an older instance still around: the current one stays
    lose(service, "service '" + service + "' restarted", out);
    make_current(service, prefix, out);
  }
  state.info = std::move(info);
  return true;
}

std::multiset<std::string>& ServiceTracker::set_of(Endpoint endpoint) {
  switch (endpoint) {
    case Endpoint::request_reader:
      return request_readers_;
    case Endpoint::reply_writer:
      return reply_writers_;
    case Endpoint::event_writer:
      return event_writers_;
    case Endpoint::group_request_reader:
      return group_request_readers_;
    case Endpoint::group_reply_writer:
      return group_reply_writers_;
  }
  return event_writers_;
}

std::optional<std::string> ServiceTracker::matched(Endpoint endpoint, const std::string& prefix,
                                                   bool matched) {
  auto& set = set_of(endpoint);
  if (matched) {
    set.insert(prefix);
  } else if (const auto it = set.find(prefix); it != set.end()) {
    set.erase(it);
  }
  const auto p = participants_.find(prefix);
  if (p == participants_.end() || !p->second.alive) return std::nullopt;
  return p->second.service;
}

bool ServiceTracker::ready(const std::string& service) const {
  const auto it = services_.find(service);
  if (it == services_.end() || !it->second.alive || it->second.incarnation.empty()) return false;
  const auto& prefix = it->second.incarnation;
  // Read-only: nothing to send, so ready means its events reach us.
  if (!can_command_) return event_writers_.count(prefix) > 0;
  return request_readers_.count(prefix) > 0 && reply_writers_.count(prefix) > 0 &&
         event_writers_.count(prefix) > 0;
}

bool ServiceTracker::group_ready(const std::string& service) const {
  if (!ready(service)) return false;
  const std::string& prefix = services_.find(service)->second.incarnation;
  return group_request_readers_.count(prefix) > 0 && group_reply_writers_.count(prefix) > 0;
}

std::string ServiceTracker::incarnation(const std::string& service) const {
  const auto it = services_.find(service);
  return it == services_.end() ? std::string{} : it->second.incarnation;
}

bool ServiceTracker::alive(const std::string& service) const {
  const auto it = services_.find(service);
  return it != services_.end() && it->second.alive;
}

bool ServiceTracker::any_alive() const {
  for (const auto& [name, state] : services_) {
    if (state.alive) return true;
  }
  return false;
}

bool ServiceTracker::participant_gone(const std::string& prefix) const {
  const auto it = participants_.find(prefix);
  return it != participants_.end() && !it->second.alive;
}

ServiceInfo ServiceTracker::info_of(const std::string& name, const ServiceState& state) const {
  ServiceInfo info = state.info.value_or(ServiceInfo{});
  info.name = name;
  info.ready = ready(name);
  return info;
}

std::vector<ServiceInfo> ServiceTracker::services() const {
  std::vector<ServiceInfo> out;
  for (const auto& [name, state] : services_) out.push_back(info_of(name, state));
  return out;
}

std::optional<ServiceInfo> ServiceTracker::service(std::string_view name) const {
  const auto it = services_.find(name);
  if (it == services_.end()) return std::nullopt;
  return info_of(it->first, it->second);
}

std::optional<ServiceInfo> ServiceTracker::find_ready(std::string_view name, bool need_info) const {
  for (const auto& [service, state] : services_) {
    if ((name.empty() || service == name) && (state.info || !need_info) && ready(service)) {
      return info_of(service, state);
    }
  }
  return std::nullopt;
}

std::map<std::string, std::optional<ServiceInfo>> ServiceTracker::ready_services() const {
  std::map<std::string, std::optional<ServiceInfo>> out;
  for (const auto& [name, state] : services_) {
    if (ready(name)) out.emplace(name, state.info);
  }
  return out;
}

std::vector<ServiceInfo> ServiceTracker::infos() const {
  std::vector<ServiceInfo> out;
  for (const auto& [name, state] : services_) {
    if (!state.info) continue;
    out.push_back(*state.info);
    out.back().name = name;
  }
  return out;
}

}  // namespace dh3::detail
