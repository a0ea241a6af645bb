// Following services: which participant serves each service now (its
// incarnation), when it is ready to take requests, and what a restart or a
// departure does to the calls written to it and to its hands.

#include <string_view>

#include "client_core.hpp"
#include "conversions.hpp"

namespace dh3::detail {

namespace {

/// The participant name dh3-service gives itself ("dh3-service <name>"): lets
/// the client know a service's participant, and so a restart, before any of
/// its samples arrive. Services of other vendors are still found by their
/// samples; only the early warning is lost.
constexpr std::string_view kServiceParticipantPrefix = "dh3-service ";

void count_match(std::multiset<std::string>& set, const std::string& prefix, bool matched) {
  if (matched) {
    set.insert(prefix);
  } else if (const auto it = set.find(prefix); it != set.end()) {
    set.erase(it);
  }
}

}  // namespace

bool ClientCore::followed(std::string_view service, std::string_view bus) const {
  if (follow_service_.empty()) return true;
  return service == follow_service_ && (bus.empty() || follow_bus_.empty() || bus == follow_bus_);
}

bool ClientCore::ready_locked(const std::string& service) const {
  const auto it = services_.find(service);
  if (it == services_.end() || !it->second.alive || it->second.incarnation.empty()) return false;
  const auto& prefix = it->second.incarnation;
  // Read-only: nothing to send, so ready means its events reach us.
  if (!can_command_) return event_writers_.count(prefix) > 0;
  return request_readers_.count(prefix) > 0 && reply_writers_.count(prefix) > 0 &&
         event_writers_.count(prefix) > 0;
}

bool ClientCore::prefix_is_dead_locked(const std::string& prefix) const {
  const auto it = participants_.find(prefix);
  return it != participants_.end() && !it->second.alive;
}

bool ClientCore::note_participant_locked(const std::string& prefix, const std::string& service,
                                         Actions& out) {
  if (service.empty() || prefix_is_dead_locked(prefix)) return false;
  auto& participant = participants_[prefix];
  participant.service = service;
  participant.alive = true;
  const auto& state = services_[service];
  if (state.incarnation.empty() || !state.alive) make_current_locked(service, prefix, out);
  return true;
}

void ClientCore::make_current_locked(const std::string& service, const std::string& prefix,
                                     Actions& out) {
  auto& state = services_[service];
  if (state.incarnation != prefix) {
    state.incarnation = prefix;
    // The info of another incarnation is not this one's.
    state.info.reset();
  }
  state.alive = true;
  changed_.notify_all();
  dispatch_locked(service, out);
}

void ClientCore::dispatch_locked(const std::string& service, Actions& out) {
  if (!ready_locked(service)) return;
  const std::string& incarnation = services_.find(service)->second.incarnation;
  for (auto& [seq, pending] : pending_) {
    if (pending.sent_to.empty() && pending.hand.service == service) {
      pending.sent_to = incarnation;
      to_write_.push_back(seq);
      out.wake_io = true;
    }
  }
  changed_.notify_all();
}

void ClientCore::lose_locked(const std::string& service, const std::string& why, Actions& out) {
  auto& state = services_[service];
  const std::string incarnation = state.incarnation;
  state.alive = false;
  if (auto it = participants_.find(incarnation); it != participants_.end()) {
    it->second.alive = false;
  }
  for (auto it = pending_.begin(); it != pending_.end();) {
    if (!incarnation.empty() && it->second.sent_to == incarnation) {
      out.completions.emplace_back(
          std::move(it->second.done),
          make_reply(Code::service_lost,
                     why + " while " + command_name(it->second.request.command()) + " for " +
                         it->second.hand.to_string() + " was pending; it may or may not have run"));
      it = pending_.erase(it);
    } else {
      ++it;
    }
  }
  for (auto& [address, status] : statuses_) {
    if (address.service != service || !status.online) continue;
    status.online = false;
    status.service_lost = true;
    post_status_locked(status);
    HandEvent event;
    event.hand = address;
    event.name = status.name;
    event.kind = EventKind::offline;
    event.position = status.position;
    event.target = status.target_position;
    event.message = why;
    event.from_client = true;
    post_event_locked(event);
  }
  changed_.notify_all();
}

void ClientCore::on_participant_found(const std::string& prefix, const std::string& name) {
  if (!std::string_view(name).starts_with(kServiceParticipantPrefix)) return;
  // A follower knows only the service it follows.
  if (!followed(std::string_view(name).substr(kServiceParticipantPrefix.size()))) return;
  Actions out;
  {
    std::lock_guard lock(mutex_);
    if (closed_) return;
    note_participant_locked(prefix, name.substr(kServiceParticipantPrefix.size()), out);
  }
  run(out);
}

void ClientCore::on_participant_left(const std::string& prefix) {
  Actions out;
  {
    std::lock_guard lock(mutex_);
    if (closed_) return;
    request_readers_.erase(prefix);
    reply_writers_.erase(prefix);
    event_writers_.erase(prefix);
    const auto it = participants_.find(prefix);
    if (it == participants_.end() || !it->second.alive) return;
    it->second.alive = false;
    const std::string service = it->second.service;
    const auto state = services_.find(service);
    if (state == services_.end() || state->second.incarnation != prefix || !state->second.alive) {
      return;
    }
    lose_locked(service, "service '" + service + "' left the domain", out);
    // Another live participant of that name (a newer instance that was not
    // yet current) takes over; the latest started first.
    const Participant* best = nullptr;
    std::string best_prefix;
    for (const auto& [other, p] : participants_) {
      if (!p.alive || p.service != service) continue;
      if (best == nullptr || (p.has_info && (!best->has_info || p.started_ns > best->started_ns))) {
        best = &p;
        best_prefix = other;
      }
    }
    if (best != nullptr) make_current_locked(service, best_prefix, out);
  }
  run(out);
}

void ClientCore::on_match(std::multiset<std::string>& set, const std::string& prefix,
                          bool matched) {
  Actions out;
  {
    std::lock_guard lock(mutex_);
    if (closed_) return;
    count_match(set, prefix, matched);
    if (const auto p = participants_.find(prefix); p != participants_.end() && p->second.alive) {
      dispatch_locked(p->second.service, out);
    }
  }
  run(out);
}

void ClientCore::on_request_reader_matched(const std::string& prefix, bool matched) {
  on_match(request_readers_, prefix, matched);
}

void ClientCore::on_reply_writer_matched(const std::string& prefix, bool matched) {
  on_match(reply_writers_, prefix, matched);
}

void ClientCore::on_event_writer_matched(const std::string& prefix, bool matched) {
  on_match(event_writers_, prefix, matched);
}

void ClientCore::on_info(const std::string& prefix, const msg::ServiceInfo& info) {
  infos_taken_.fetch_add(1, std::memory_order_relaxed);
  if (!followed(info.service())) return;
  Actions out;
  {
    std::lock_guard lock(mutex_);
    if (closed_ || !note_participant_locked(prefix, info.service(), out)) return;
    auto& participant = participants_[prefix];
    participant.has_info = true;
    participant.started_ns = info.started_ns();
    auto& state = services_[info.service()];
    if (state.incarnation != prefix) {
      const auto current = participants_.find(state.incarnation);
      const bool newer = current == participants_.end() || !current->second.has_info ||
                         info.started_ns() > current->second.started_ns;
      if (!newer) return;  // an older instance still around: the current one stays
      lose_locked(info.service(), "service '" + info.service() + "' restarted", out);
      make_current_locked(info.service(), prefix, out);
    }
    state.info = to_public(info);
    changed_.notify_all();
  }
  run(out);
}

}  // namespace dh3::detail
