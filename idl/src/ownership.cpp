#include "dh3/contract/ownership.hpp"

#include <algorithm>
#include <tuple>
#include <utility>

namespace dh3::contract {

std::optional<std::string> announced_service(std::string_view participant_name) {
  if (!participant_name.starts_with(kServiceParticipantPrefix)) return std::nullopt;
  return std::string(participant_name.substr(kServiceParticipantPrefix.size()));
}

std::string OwnerClaim::describe() const {
  return "pid " + std::to_string(pid) + " on host '" + host + "' (participant " + participant + ")";
}

OwnerClaim to_claim(const msg::ServiceOwner& sample, const std::string& participant) {
  OwnerClaim claim;
  claim.participant = participant;
  claim.service = sample.service();
  claim.host = sample.host();
  claim.pid = sample.pid();
  claim.started_ns = sample.started_ns();
  claim.standby = sample.role() == msg::ServiceRole::ROLE_STANDBY;
  claim.epoch = sample.epoch();
  return claim;
}

bool outranks(const OwnerClaim& a, const OwnerClaim& b) {
  return std::tie(a.epoch, a.started_ns, a.participant) >
         std::tie(b.epoch, b.started_ns, b.participant);
}

// ---------------------------------------------------------------------------
// OwnerTable

void OwnerTable::claim(OwnerClaim claim) {
  auto& entry = entries_[claim.participant];
  entry.claim = std::move(claim);
  entry.has_claim = true;
}

void OwnerTable::set_alive(const std::string& participant, bool alive) {
  entries_[participant].liveliness = alive ? Liveliness::alive : Liveliness::lapsed;
}

bool OwnerTable::liveliness_changed(const std::string& participant, int change) {
  Entry& entry = entries_[participant];
  entry.liveliness_reported = true;
  entry.liveliness_sum = std::max(0, entry.liveliness_sum + change);
  return entry.liveliness_sum > 0;
}

void OwnerTable::forget(const std::string& participant) {
  entries_.erase(participant);
}

void OwnerTable::announced(const std::string& participant, std::string service) {
  entries_[participant].announced_service = std::move(service);
}

bool OwnerTable::claim_awaited(std::string_view service) const {
  return std::any_of(entries_.begin(), entries_.end(), [service](const auto& participant_entry) {
    const Entry& entry = participant_entry.second;
    return !entry.has_claim && entry.announced_service == service;
  });
}

std::optional<OwnerClaim> OwnerTable::claim_of(const std::string& participant) const {
  const auto it = entries_.find(participant);
  if (it == entries_.end() || !it->second.has_claim) return std::nullopt;
  return it->second.claim;
}

bool OwnerTable::alive(const std::string& participant) const {
  const auto it = entries_.find(participant);
  return it != entries_.end() && it->second.liveliness == Liveliness::alive;
}

bool OwnerTable::liveliness_reported(const std::string& participant) const {
  const auto it = entries_.find(participant);
  return it != entries_.end() && it->second.liveliness_reported;
}

bool OwnerTable::lapsed(const std::string& participant) const {
  const auto it = entries_.find(participant);
  return it != entries_.end() && it->second.liveliness == Liveliness::lapsed;
}

std::optional<OwnerClaim> OwnerTable::owner(std::string_view service) const {
  std::optional<OwnerClaim> best;
  for (const auto& [participant, entry] : entries_) {
    if (!entry.has_claim || entry.liveliness == Liveliness::lapsed || entry.claim.standby) {
      continue;
    }
    if (entry.claim.service != service) continue;
    if (!best || outranks(entry.claim, *best)) best = entry.claim;
  }
  return best;
}

std::vector<OwnerClaim> OwnerTable::standbys(std::string_view service) const {
  std::vector<OwnerClaim> found;
  for (const auto& [participant, entry] : entries_) {
    if (entry.has_claim && entry.claim.standby && entry.liveliness != Liveliness::lapsed &&
        entry.claim.service == service) {
      found.push_back(entry.claim);
    }
  }
  return found;
}

std::uint64_t OwnerTable::highest_epoch(std::string_view service) const {
  std::uint64_t highest = 0;
  for (const auto& [participant, entry] : entries_) {
    if (entry.has_claim && entry.claim.service == service) {
      highest = std::max(highest, entry.claim.epoch);
    }
  }
  return highest;
}

// ---------------------------------------------------------------------------
// StartClaim

StartClaim::StartClaim(std::string service, std::string self, Duration window, const Clock& clock)
    : service_(std::move(service)),
      self_(std::move(self)),
      deadline_(clock.now() + window),
      clock_(clock) {}

StartClaim::Verdict StartClaim::decide(const OwnerTable& table) {
  if (const auto owner = table.owner(service_); owner && owner->participant != self_) {
    other_ = owner;
    return Verdict::refuse;
  }
  const TimePoint now = clock_.now();
  if (now < deadline_) return Verdict::wait;
  if (table.claim_awaited(service_) && now < deadline_ + kStartClaimAwait) return Verdict::wait;
  return Verdict::serve;
}

std::uint64_t StartClaim::epoch(const OwnerTable& table) const {
  return table.highest_epoch(service_) + 1;
}

}  // namespace dh3::contract
