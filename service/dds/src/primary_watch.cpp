#include "primary_watch.hpp"

#include <tuple>
#include <utility>

namespace dh3::dds {

PrimaryWatch::PrimaryWatch(contract::OwnerClaim self, TimePoint started,
                           std::optional<Duration> vacancy_wait)
    : self_(std::move(self)) {
  if (vacancy_wait) vacant_from_ = started + *vacancy_wait;
}

std::optional<PrimaryLapse> PrimaryWatch::look(const OwnerView& view, TimePoint now,
                                               std::optional<TimePoint> buses_silent_at,
                                               bool* changed) {
  if (changed) *changed = false;
  if (view.owner) {
    if (changed) *changed = !primary_ || primary_->participant != view.owner->participant;
    primary_ = view.owner;
    lost_since_.reset();
    return std::nullopt;
  }
  if (primary_) {
    if (!lost_since_) lost_since_ = now;
    const bool confirmed = now - *lost_since_ >= contract::kOwnerLapseConfirm ||
                           (buses_silent_at && *buses_silent_at >= *lost_since_);
    if (!confirmed || !senior(view)) return std::nullopt;
    return PrimaryLapse{primary_, *lost_since_, view.highest_epoch};
  }
  if (!vacant_from_ || now < *vacant_from_) return std::nullopt;
  if (view.claim_awaited && now < *vacant_from_ + contract::kStartClaimAwait) return std::nullopt;
  if (!senior(view)) return std::nullopt;
  return PrimaryLapse{std::nullopt, *vacant_from_, view.highest_epoch};
}

bool PrimaryWatch::senior(const OwnerView& view) const {
  for (const auto& other : view.standbys) {
    if (other.participant == self_.participant) continue;
    if (std::tie(other.started_ns, other.participant) <
        std::tie(self_.started_ns, self_.participant)) {
      return false;
    }
  }
  return true;
}

}  // namespace dh3::dds
