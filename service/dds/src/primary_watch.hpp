#pragma once
// A standby's judgement of the cell it stands by for (StandbyPresence), told
// what the owner topic shows each time it looks. It may take the cell when:
// - the primary is lost: an owner was seen and none has been for
//   contract::kOwnerLapseConfirm, the confirmation a client applies before
//   it believes a lapse, or the buses already confirm it: a read of every
//   bus after the lapse began found it silent (the primary drove it, then
//   sent nothing for the fence's quiet time). The confirmation guards
//   against a standby that stalled itself and has not yet read the
//   assertions queued meanwhile; a bus read since then that found no
//   request in the quiet time is the primary's own silence. A lapse
//   overturned sooner (a frozen owner asserting again) is forgotten;
// - or the cell is vacant: no owner was seen in the vacancy wait after the
//   standby started, and no claim of a participant that discovery announced
//   as a service or a standby of the name is still awaited (at most
//   contract::kStartClaimAwait longer, as a starting service waits). Nobody
//   serves the cell: the standby started first, or its primary never came up.
//   A watch without a vacancy wait takes over only from an owner it saw.
// Either way only the senior of the name's standbys takes it (the one that
// started first, then the lower participant prefix): the two members of a
// pair started together, or two standbys of one owner, that see each other
// do not both serve.
// Pure and single-threaded: tested on a fake clock.

#include <cstdint>
#include <optional>
#include <vector>

#include "dh3/base/clock.hpp"
#include "dh3/contract/ownership.hpp"
#include "dh3/dds/standby_presence.hpp"

namespace dh3::dds {

/// What the owner topic shows of a name at one moment (contract::OwnerTable).
struct OwnerView {
  std::optional<contract::OwnerClaim> owner;   ///< OwnerTable::owner
  std::uint64_t highest_epoch = 0;             ///< OwnerTable::highest_epoch
  std::vector<contract::OwnerClaim> standbys;  ///< OwnerTable::standbys, ours among them or not
  bool claim_awaited = false;                  ///< a claimant announced, its claim not arrived
};

class PrimaryWatch {
 public:
  /// `self`: this standby's claim (its participant and start rank it among
  /// the standbys); `vacancy_wait`: how long after `started` a cell that no
  /// owner served counts as vacant, nullopt: never.
  PrimaryWatch(contract::OwnerClaim self, TimePoint started, std::optional<Duration> vacancy_wait);

  /// The confirmed loss of the primary, or the cell's vacancy (a lapse
  /// without a primary), when this standby is to take the cell; nullopt
  /// otherwise. `buses_silent_at`: the last time a read of every bus found
  /// it silent (StandbyWatch::silent_at), nullopt if a bus is not. `changed`
  /// is set when the owner is not the one seen before.
  std::optional<PrimaryLapse> look(const OwnerView& view, TimePoint now,
                                   std::optional<TimePoint> buses_silent_at = std::nullopt,
                                   bool* changed = nullptr);

 private:
  /// No other standby of the name started before this one.
  [[nodiscard]] bool senior(const OwnerView& view) const;

  contract::OwnerClaim self_;
  std::optional<TimePoint> vacant_from_;
  std::optional<contract::OwnerClaim> primary_;
  std::optional<TimePoint> lost_since_;
};

}  // namespace dh3::dds
