#include "lease_table.hpp"

#include <cctype>

namespace dh3::dds {

std::string canonical_client_id(std::string_view id) {
  std::string out;
  out.reserve(id.size());
  for (const char c : id) {
    if (c == '.' || c == ':') continue;
    out.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
  }
  return out;
}

const LeaseTable::Lease* LeaseTable::live_locked(HandKey hand, TimePoint now) const {
  const auto it = leases_.find(hand);
  if (it == leases_.end() || it->second.expires <= now) return nullptr;
  return &it->second;
}

LeaseAnswer LeaseTable::acquire(HandKey hand, std::string_view client, Duration ttl,
                                std::string_view shown_as) {
  const TimePoint now = clock_.now();
  if (shown_as.empty()) shown_as = client;
  LeaseAnswer answer;
  {
    std::lock_guard lock(mutex_);
    if (const Lease* lease = live_locked(hand, now); lease != nullptr && lease->holder != client) {
      return {LeaseOutcome::held_by_other, lease->shown, false};
    }
    auto [it, inserted] = leases_.try_emplace(hand);
    const bool changed = inserted || it->second.holder != client ||
                         it->second.shown != shown_as || it->second.expires <= now;
    it->second.holder.assign(client);
    it->second.shown.assign(shown_as);
    it->second.expires = now + ttl;
    count_.store(leases_.size());
    answer = {LeaseOutcome::granted, it->second.shown, changed};
  }
  tell_changed(hand);
  return answer;
}

LeaseAnswer LeaseTable::renew(HandKey hand, std::string_view client, Duration ttl) {
  const TimePoint now = clock_.now();
  LeaseAnswer answer;
  {
    std::lock_guard lock(mutex_);
    const auto it = leases_.find(hand);
    if (it == leases_.end() || it->second.expires <= now) {
      return {LeaseOutcome::not_held, {}, false};
    }
    if (it->second.holder != client) return {LeaseOutcome::held_by_other, it->second.shown, false};
    it->second.expires = now + ttl;
    answer = {LeaseOutcome::granted, it->second.shown, false};
  }
  tell_changed(hand);
  return answer;
}

LeaseAnswer LeaseTable::release(HandKey hand, std::string_view client) {
  const TimePoint now = clock_.now();
  {
    std::lock_guard lock(mutex_);
    const auto it = leases_.find(hand);
    if (it == leases_.end()) return {LeaseOutcome::granted, {}, false};
    if (it->second.expires > now && it->second.holder != client) {
      return {LeaseOutcome::held_by_other, it->second.shown, false};
    }
    // An expired lease still in the table ends here; its end was not yet published.
    leases_.erase(it);
    count_.store(leases_.size());
  }
  tell_changed(hand);
  return {LeaseOutcome::granted, {}, true};
}

std::optional<std::string> LeaseTable::blocking_holder(HandKey hand,
                                                       std::string_view client) const {
  if (count_.load(std::memory_order_relaxed) == 0) return std::nullopt;
  const TimePoint now = clock_.now();
  std::lock_guard lock(mutex_);
  const Lease* lease = live_locked(hand, now);
  if (lease == nullptr || lease->holder == client) return std::nullopt;
  return lease->shown;
}

std::optional<std::string> LeaseTable::blocking_holder_on_bus(std::uint16_t bus,
                                                              std::string_view client) const {
  if (count_.load(std::memory_order_relaxed) == 0) return std::nullopt;
  const TimePoint now = clock_.now();
  std::lock_guard lock(mutex_);
  for (auto it = leases_.lower_bound(HandKey{bus, 0}); it != leases_.end() && it->first.bus == bus;
       ++it) {
    if (it->second.expires > now && it->second.holder != client) return it->second.shown;
  }
  return std::nullopt;
}

std::string LeaseTable::holder(HandKey hand) const {
  if (count_.load(std::memory_order_relaxed) == 0) return {};
  const TimePoint now = clock_.now();
  std::lock_guard lock(mutex_);
  const Lease* lease = live_locked(hand, now);
  return lease != nullptr ? lease->shown : std::string{};
}

bool LeaseTable::held_by(HandKey hand, std::string_view client) const {
  if (count_.load(std::memory_order_relaxed) == 0) return false;
  const std::string wanted = canonical_client_id(client);
  const TimePoint now = clock_.now();
  std::lock_guard lock(mutex_);
  const Lease* lease = live_locked(hand, now);
  return lease != nullptr && !wanted.empty() && canonical_client_id(lease->holder) == wanted;
}

std::vector<EndedLease> LeaseTable::end_locked(const std::function<bool(const Lease&)>& ends) {
  std::vector<EndedLease> ended;
  for (auto it = leases_.begin(); it != leases_.end();) {
    if (ends(it->second)) {
      ended.push_back({it->first, std::move(it->second.shown), std::move(it->second.holder)});
      it = leases_.erase(it);
    } else {
      ++it;
    }
  }
  count_.store(leases_.size());
  return ended;
}

std::vector<EndedLease> LeaseTable::expire() {
  const TimePoint now = clock_.now();
  std::vector<EndedLease> ended;
  {
    std::lock_guard lock(mutex_);
    ended = end_locked([now](const Lease& lease) { return lease.expires <= now; });
  }
  tell_ended(ended);
  return ended;
}

std::vector<EndedLease> LeaseTable::drop_client(std::string_view participant_id) {
  const std::string wanted = canonical_client_id(participant_id);
  if (wanted.empty()) return {};
  std::vector<EndedLease> ended;
  {
    std::lock_guard lock(mutex_);
    ended = end_locked(
        [&wanted](const Lease& lease) { return canonical_client_id(lease.holder) == wanted; });
  }
  tell_ended(ended);
  return ended;
}

std::optional<TimePoint> LeaseTable::next_expiry() const {
  std::lock_guard lock(mutex_);
  std::optional<TimePoint> earliest;
  for (const auto& [hand, lease] : leases_) {
    if (!earliest || lease.expires < *earliest) earliest = lease.expires;
  }
  return earliest;
}

std::optional<HeldLease> LeaseTable::lease_of(HandKey hand) const {
  const TimePoint now = clock_.now();
  std::lock_guard lock(mutex_);
  const Lease* lease = live_locked(hand, now);
  if (lease == nullptr) return std::nullopt;
  return HeldLease{hand, lease->holder, lease->shown, lease->expires - now};
}

std::vector<HeldLease> LeaseTable::leases() const {
  const TimePoint now = clock_.now();
  std::lock_guard lock(mutex_);
  std::vector<HeldLease> held;
  for (const auto& [hand, lease] : leases_) {
    if (lease.expires > now) held.push_back({hand, lease.holder, lease.shown, lease.expires - now});
  }
  return held;
}

void LeaseTable::load(const std::vector<HeldLease>& leases) {
  const TimePoint now = clock_.now();
  std::vector<HandKey> loaded;
  {
    std::lock_guard lock(mutex_);
    for (const auto& lease : leases) {
      if (lease.left <= Duration::zero() || lease.holder_id.empty()) continue;
      leases_[lease.hand] = {lease.holder_id,
                             lease.holder.empty() ? lease.holder_id : lease.holder,
                             now + lease.left};
      loaded.push_back(lease.hand);
    }
    count_.store(leases_.size());
  }
  for (const HandKey hand : loaded) tell_changed(hand);
}

}  // namespace dh3::dds
