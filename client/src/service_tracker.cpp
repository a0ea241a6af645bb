// ServiceTracker: services' incarnations, their readiness, restarts and losses.

#include "service_tracker.hpp"

#include <algorithm>

namespace dh3::detail {

bool ServiceTracker::note_participant(const std::string& prefix, const std::string& service,
                                      Outcome& out, std::chrono::steady_clock::time_point now) {
  if (service.empty() || !believed(prefix, service)) return false;
  auto& participant = participants_[prefix];
  participant.service = service;
  participant.alive = true;
  const auto& state = services_[service];
  if (state.incarnation.empty() || !state.alive) make_current(service, prefix, out);
  start_owner_wait(prefix, now);
  return true;
}

bool ServiceTracker::participant_found(const std::string& prefix, const std::string& service,
                                       Outcome& out, std::chrono::steady_clock::time_point now) {
  announced_[prefix] = service;
  if (const auto it = participants_.find(prefix); it != participants_.end()) {
    it->second.alive = true;
  }
  return note_participant(prefix, service, out, now);
}

bool ServiceTracker::note_status(const std::string& prefix, const std::string& service,
                                 Outcome& out) {
  if (owners_.lapsed(prefix) && owners_.claim_of(prefix) && !owners_.liveliness_reported(prefix)) {
    owners_.liveliness_changed(prefix, +1);  // the report Fast DDS dropped
    out = owner_alive(prefix, true);
  }
  return note_participant(prefix, service, out);
}

void ServiceTracker::set_endpoints(bool can_command, bool has_owner_reader,
                                   std::chrono::steady_clock::time_point now) {
  can_command_ = can_command;
  owner_reader_ = has_owner_reader;
  for (const auto& [prefix, participant] : participants_) start_owner_wait(prefix, now);
}

bool ServiceTracker::endpoints_matched(const std::string& prefix) const {
  // Read-only: nothing to send, so its events reaching us is all.
  if (!can_command_) return event_writers_.count(prefix) > 0;
  return request_readers_.count(prefix) > 0 && reply_writers_.count(prefix) > 0 &&
         event_writers_.count(prefix) > 0;
}

void ServiceTracker::start_owner_wait(const std::string& prefix,
                                      std::chrono::steady_clock::time_point now) {
  const auto it = participants_.find(prefix);
  if (!owner_reader_ || it == participants_.end() || it->second.owner_wait_until) return;
  if (endpoints_matched(prefix)) it->second.owner_wait_until = now + kOwnerWait;
}

std::string ServiceTracker::describe(const std::string& prefix) const {
  if (const auto claim = owners_.claim_of(prefix)) return claim->describe();
  return "participant " + prefix;
}

void ServiceTracker::make_current(const std::string& service, const std::string& prefix,
                                  Outcome& out) {
  auto& state = services_[service];
  if (state.incarnation != prefix) {
    if (!state.incarnation.empty()) {
      out.taken_over_from = describe(state.incarnation);
      out.taken_over_by = describe(prefix);
    }
    state.incarnation = prefix;
    // The info of another incarnation is not this one's.
    const auto it = participants_.find(prefix);
    state.info = it != participants_.end() ? it->second.info : std::nullopt;
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

bool ServiceTracker::believed(const std::string& prefix, std::string_view service) const {
  if (const auto owner = owners_.owner(service)) return owner->participant == prefix;
  // A claimant that is not the owner: dead, frozen, outranked or a standby.
  if (owners_.claim_of(prefix)) return false;
  return !participant_gone(prefix);
}

void ServiceTracker::take_claim(const contract::OwnerClaim& claim, Outcome& out,
                                std::chrono::steady_clock::time_point now) {
  owners_.claim(claim);
  if (!owners_.alive(claim.participant) && !owners_.lapsed(claim.participant)) {
    owner_lapsed(claim.participant, now + contract::kOwnerLease);  // undone by its first assertion
  }
  follow_owner(claim.service, out);
  out.service = claim.service;
  out.may_dispatch = true;  // its calls may go out, if this made it ready
}

ServiceTracker::Outcome ServiceTracker::owner_alive(const std::string& prefix, bool alive) {
  Outcome out;
  lapses_.erase(prefix);
  owners_.set_alive(prefix, alive);
  if (const auto claim = owners_.claim_of(prefix)) {
    follow_owner(claim->service, out);
    out.service = claim->service;
    out.may_dispatch = true;  // its calls may go out, if this made it ready
  }
  return out;
}

void ServiceTracker::owner_lapsed(const std::string& prefix,
                                  std::chrono::steady_clock::time_point now) {
  lapses_.try_emplace(prefix, now);
}

std::vector<ServiceTracker::Outcome> ServiceTracker::confirm_lapses(
    std::chrono::steady_clock::time_point now) {
  std::vector<Outcome> out;
  for (auto& [prefix, participant] : participants_) {
    if (participant.owner_waived || !participant.owner_wait_until ||
        *participant.owner_wait_until > now) {
      continue;
    }
    participant.owner_waived = true;
    Outcome waived;
    waived.service = participant.service;
    waived.may_dispatch = true;  // ready without its owner writer, if it was waiting for it
    out.push_back(std::move(waived));
  }
  std::optional<ReceiveState> seen;  // one look for every lapse that wants one
  for (auto it = lapses_.begin(); it != lapses_.end();) {
    Lapse& lapse = it->second;
    if (lapse.judge.next_look() <= now) {
      if (!seen) seen = look_();
      lapse.judge.take(now, *seen);
    }
    if (!lapse.believed && lapse.confirm_at <= now) {
      // The service is lost for statuses, events and new calls; its calls in
      // flight wait for the judge (a lapse the owner overturns ends none).
      lapse.believed = true;
      owners_.set_alive(it->first, false);
      if (const auto claim = owners_.claim_of(it->first)) {
        Outcome lost;
        follow_owner(claim->service, lost);
        lost.keep_calls = true;
        lapse.incarnation = lost.lost;
        lapse.why = lost.why;
        out.push_back(std::move(lost));
      }
    }
    if (lapse.believed && lapse.judge.calls_end(now)) {
      Outcome calls;
      calls.end_calls_of = lapse.incarnation;
      calls.why = lapse.why;
      out.push_back(std::move(calls));
      it = lapses_.erase(it);
      continue;
    }
    ++it;
  }
  return out;
}

std::chrono::steady_clock::time_point ServiceTracker::next_lapse() const {
  auto next = std::chrono::steady_clock::time_point::max();
  for (const auto& [prefix, lapse] : lapses_) {
    next = std::min({next, lapse.judge.next_look(),
                     lapse.believed ? lapse.judge.blind_end() : lapse.confirm_at});
  }
  for (const auto& [prefix, participant] : participants_) {
    if (!participant.owner_waived && participant.owner_wait_until) {
      next = std::min(next, *participant.owner_wait_until);
    }
  }
  return next;
}

void ServiceTracker::follow_owner(const std::string& service, Outcome& out) {
  const auto owner = owners_.owner(service);
  auto& state = services_[service];
  if (owner) {
    if (state.incarnation == owner->participant && state.alive) return;
    if (state.alive && !state.incarnation.empty()) {
      lose(service, "service '" + service + "' is now served by " + owner->describe(), out);
    } else if (const auto lapse = lapses_.find(state.incarnation);
               state.incarnation != owner->participant && lapse != lapses_.end() &&
               lapse->second.believed) {
      // A lapsed owner's calls in flight wait for its return no longer:
      // another owner serves the name (a standby took over), and no reply of
      // the old one would be believed.
      out.end_calls_of = state.incarnation;
      out.why = "service '" + service + "' is now served by " + owner->describe() + " (" +
                lapse->second.why + ")";
      lapses_.erase(lapse);
    }
    auto& participant = participants_[owner->participant];
    participant.service = service;
    if (state.incarnation == owner->participant) out.regained = owner->participant;
    participant.alive = true;  // again, if its liveliness had lapsed
    make_current(service, owner->participant, out);
    return;
  }
  // No owner: the current one, if it was a claimant, stopped asserting. One
  // whose liveliness was never seen is not lost for that: unknown is not dead.
  const auto lapsed = owners_.claim_of(state.incarnation);
  if (state.alive && lapsed && owners_.lapsed(state.incarnation)) {
    lose(service,
         "service '" + service + "' (" + lapsed->describe() +
             ") stopped asserting it lives: no "
             "sign of it for " +
             std::to_string((contract::kOwnerLease + contract::kOwnerLapseConfirm).count()) +
             " ms (killed, frozen or cut off)",
         out);
  }
}

ServiceTracker::Outcome ServiceTracker::participant_left(const std::string& prefix) {
  Outcome out;
  owners_.forget(prefix);
  lapses_.erase(prefix);
  request_readers_.erase(prefix);
  reply_writers_.erase(prefix);
  event_writers_.erase(prefix);
  owner_writers_.erase(prefix);
  admin_request_readers_.erase(prefix);
  const auto it = participants_.find(prefix);
  if (it == participants_.end() || !it->second.alive) return out;
  it->second.alive = false;
  const std::string service = it->second.service;
  const auto state = services_.find(service);
  if (state == services_.end() || state->second.incarnation != prefix || !state->second.alive) {
    return out;
  }
  lose(service, "service '" + service + "' left the domain", out);
  if (owners_.owner(service)) {
    follow_owner(service, out);
    return out;
  }
  // Another live participant of that name (a newer instance that was not yet
  // current) takes over; the latest started first.
  const Participant* best = nullptr;
  std::string best_prefix;
  for (const auto& [other, p] : participants_) {
    if (!p.alive || p.service != service || !believed(other, service)) continue;
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
  if (!service.empty() && !participant_gone(prefix)) {
    auto& kept = participants_[prefix];
    kept.service = service;
    kept.info = info;
  }
  if (!note_participant(prefix, service, out)) return false;
  auto& participant = participants_[prefix];
  participant.has_info = true;
  participant.started_ns = info.started_ns;
  auto& state = services_[service];
  // The owner rule decides, once claims are known (note_participant kept only the owner).
  if (state.incarnation != prefix && !owners_.owner(service)) {
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
    case Endpoint::owner_writer:
      return owner_writers_;
    case Endpoint::admin_request_reader:
      return admin_request_readers_;
  }
  return event_writers_;
}

std::optional<std::string> ServiceTracker::matched(Endpoint endpoint, const std::string& prefix,
                                                   bool matched,
                                                   std::chrono::steady_clock::time_point now) {
  auto& set = set_of(endpoint);
  if (matched) {
    set.insert(prefix);
  } else if (const auto it = set.find(prefix); it != set.end()) {
    set.erase(it);
  }
  const auto p = participants_.find(prefix);
  if (p == participants_.end() || !p->second.alive) return std::nullopt;
  start_owner_wait(prefix, now);
  return p->second.service;
}

bool ServiceTracker::ready(const std::string& service) const {
  const auto it = services_.find(service);
  if (it == services_.end() || !it->second.alive || it->second.incarnation.empty()) return false;
  const auto& prefix = it->second.incarnation;
  if (!owners_.alive(prefix) || !owners_.claim_of(prefix)) {
    // Its owner writer matched: ready once its claim arrived and it was seen
    // alive (in either order), so that a death has a claim to lose.
    // Otherwise, reading claims, wait for it until kOwnerWait has passed.
    if (owner_writers_.count(prefix) > 0) return false;
    const auto p = participants_.find(prefix);
    if (owner_reader_ && (p == participants_.end() || !p->second.owner_waived)) return false;
  }
  return endpoints_matched(prefix);
}

bool ServiceTracker::group_ready(const std::string& service) const {
  if (!ready(service)) return false;
  const std::string& prefix = services_.find(service)->second.incarnation;
  return group_request_readers_.count(prefix) > 0 && group_reply_writers_.count(prefix) > 0;
}

bool ServiceTracker::admin_ready(const std::string& service) const {
  if (!ready(service)) return false;
  return admin_request_readers_.count(services_.find(service)->second.incarnation) > 0;
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

std::string ServiceTracker::unmatched(const std::string& prefix) const {
  std::string missing;
  const auto lacks = [&](const std::multiset<std::string>& matched, const char* endpoint) {
    if (matched.count(prefix) == 0)
      missing += (missing.empty() ? "" : ", ") + std::string(endpoint);
  };
  if (can_command_) {
    lacks(request_readers_, "request reader");
    lacks(reply_writers_, "reply writer");
    lacks(group_request_readers_, "group request reader");
    lacks(group_reply_writers_, "group reply writer");
  }
  lacks(event_writers_, "event writer");
  return missing;
}

std::string ServiceTracker::sightings(const std::string& service) const {
  std::string seen;
  for (const auto& [prefix, announced] : announced_) {
    if (announced != service) continue;
    std::string why;
    if (participant_gone(prefix)) {
      why = "it left the domain or stopped asserting it lives";
    } else if (believed(prefix, service)) {
      why = "believed";
      const std::string missing = unmatched(prefix);
      if (!missing.empty()) why += ", its " + missing + " not matched with this client";
    } else if (const auto owner = owners_.owner(service)) {
      why = "not believed: the owner is " + owner->describe();
    } else if (owners_.lapsed(prefix)) {
      why = "not believed: its owner liveliness lapsed";
    } else {
      why = "not believed: a standby or outranked claimant";
    }
    seen += (seen.empty() ? "" : "; ") + describe(prefix) + ": " + why;
  }
  if (seen.empty()) return "discovery found no participant announcing it";
  return "discovery found " + seen;
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
