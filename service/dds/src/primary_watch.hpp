#pragma once
// A standby's judgement of its active service (StandbyPresence), told the
// owner of the name each time it looks: the primary is lost once an owner
// was seen and none has been for contract::kOwnerLapseConfirm, the
// confirmation a client applies before it believes a lapse. A lapse
// overturned sooner (a frozen owner asserting again) is forgotten; a standby
// that never saw an owner never judges one lost.
// Pure and single-threaded: tested on a fake clock.

#include <optional>

#include "dh3/base/clock.hpp"
#include "dh3/contract/ownership.hpp"
#include "dh3/dds/standby_presence.hpp"

namespace dh3::dds {

class PrimaryWatch {
 public:
  /// `owner`: the owner of the name at `now` (OwnerTable::owner);
  /// `highest_epoch`: the highest epoch claimed on it. The confirmed loss, or
  /// nullopt. `changed` is set when the owner is not the one seen before.
  std::optional<PrimaryLapse> look(const std::optional<contract::OwnerClaim>& owner,
                                   std::uint64_t highest_epoch, TimePoint now,
                                   bool* changed = nullptr) {
    if (owner) {
      if (changed) *changed = !primary_ || primary_->participant != owner->participant;
      primary_ = owner;
      lost_since_.reset();
      return std::nullopt;
    }
    if (!primary_) return std::nullopt;
    if (!lost_since_) lost_since_ = now;
    if (now - *lost_since_ < contract::kOwnerLapseConfirm) return std::nullopt;
    return PrimaryLapse{*primary_, *lost_since_, highest_epoch};
  }

 private:
  std::optional<contract::OwnerClaim> primary_;
  std::optional<TimePoint> lost_since_;
};

}  // namespace dh3::dds
