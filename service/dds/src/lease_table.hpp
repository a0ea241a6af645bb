#pragma once
// Control leases: a client that holds a hand's lease is the only one whose
// motion and write commands that hand accepts; reads and status stay open to
// everyone. A lease ends when its holder releases it, when it is not renewed
// within its time to live, or when the holder's participant leaves the domain.
// Without a lease, the last command wins.
//
// A client is its participant: the service names it by the id of the
// participant that wrote the request (contract::client_id_for), never by a
// field of the request. People see the holder under the name it is shown as
// (its participant's announced name), which is no credential.
//
// A standby learns the table (LeasePublisher writes each change, LeaseFollower
// reads it) and the service that takes over loads it: leases() and load()
// carry each lease with its holder and the time it has left.
//
// Thread-safe: requests (DDS listener threads), the expiry timer and the
// participant listener all use one table. Knows no DDS.

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dh3/base/clock.hpp"

namespace dh3::dds {

/// A hand inside one service: its bus's index and its CAN ID.
struct HandKey {
  std::uint16_t bus = 0;
  std::uint8_t can_id = 0;

  friend auto operator<=>(const HandKey&, const HandKey&) = default;
};

enum class LeaseOutcome : std::uint8_t {
  granted,        ///< acquired, renewed, or released
  held_by_other,  ///< another client holds the hand's lease
  not_held,       ///< renew by a client that holds no lease on the hand
};

struct LeaseAnswer {
  LeaseOutcome outcome = LeaseOutcome::granted;
  /// The holder after the call, as shown (empty if none); for held_by_other,
  /// who holds it.
  std::string holder;
  /// True if the holder changed (a status sample should say so).
  bool holder_changed = false;
};

/// A lease that ended without its holder asking.
struct EndedLease {
  HandKey hand;
  std::string holder;     ///< as shown
  std::string holder_id;  ///< the client id
};

/// A live lease and the time it has left.
struct HeldLease {
  HandKey hand;
  std::string holder_id;  ///< the client id
  std::string holder;     ///< as shown
  Duration left{};
};

class LeaseTable {
 public:
  /// Told the hand whose lease changed (taken, extended, released or
  /// ended), after the change, outside the table's lock.
  using Changed = std::function<void(HandKey hand)>;

  explicit LeaseTable(const Clock& clock) : clock_(clock) {}

  /// Set once, before the table is used from more than one thread.
  void on_change(Changed changed) { changed_ = std::move(changed); }

  /// Takes the lease, or extends it if `client` already holds it. The holder is
  /// shown as `shown_as` (the id itself when empty).
  LeaseAnswer acquire(HandKey hand, std::string_view client, Duration ttl,
                      std::string_view shown_as = {});
  /// Extends a lease `client` holds.
  LeaseAnswer renew(HandKey hand, std::string_view client, Duration ttl);
  /// Gives the lease up. Releasing a lease nobody holds is granted (nothing to do).
  LeaseAnswer release(HandKey hand, std::string_view client);

  /// Who keeps `client` from commanding `hand`: the holder as shown, or nullopt if the
  /// hand is free or `client` holds it. Cheap when no lease is held at all.
  [[nodiscard]] std::optional<std::string> blocking_holder(HandKey hand,
                                                           std::string_view client) const;
  /// Like blocking_holder() for every hand of a bus (a command to CAN ID 0
  /// reaches whichever hand is there).
  [[nodiscard]] std::optional<std::string> blocking_holder_on_bus(std::uint16_t bus,
                                                                  std::string_view client) const;
  /// The current holder of `hand` as shown, empty if none (expired leases count as none).
  [[nodiscard]] std::string holder(HandKey hand) const;
  /// Whether `client` (compared as canonical_client_id) holds `hand`'s live lease.
  [[nodiscard]] bool held_by(HandKey hand, std::string_view client) const;

  /// Ends leases whose time ran out at clock.now() and returns them.
  std::vector<EndedLease> expire();
  /// Ends every lease of a client whose participant left. `participant_id` is
  /// compared with client ids ignoring case and '.'/':' separators, so
  /// "01.0F.A2..." and "010fa2..." name the same participant.
  std::vector<EndedLease> drop_client(std::string_view participant_id);
  /// When the next lease runs out, nullopt if none is held.
  [[nodiscard]] std::optional<TimePoint> next_expiry() const;

  /// The live lease on `hand`, nullopt if the hand is free.
  [[nodiscard]] std::optional<HeldLease> lease_of(HandKey hand) const;
  /// Every live lease.
  [[nodiscard]] std::vector<HeldLease> leases() const;
  /// Takes over leases another service granted (a takeover): each runs out
  /// when its time left from now does, and replaces what the table held for
  /// its hand. Leases with no time left are skipped.
  void load(const std::vector<HeldLease>& leases);

 private:
  struct Lease {
    std::string holder;  ///< the client id
    std::string shown;   ///< how people see the holder
    TimePoint expires;
  };
  /// The live lease on `hand`, nullopt if none or it ran out (locked).
  [[nodiscard]] const Lease* live_locked(HandKey hand, TimePoint now) const;
  /// Ends the leases `ends` picks and returns them (locked).
  std::vector<EndedLease> end_locked(const std::function<bool(const Lease&)>& ends);
  void tell_changed(HandKey hand) const {
    if (changed_) changed_(hand);
  }
  void tell_ended(const std::vector<EndedLease>& ended) const {
    for (const auto& lease : ended) tell_changed(lease.hand);
  }

  const Clock& clock_;
  Changed changed_;
  mutable std::mutex mutex_;
  std::map<HandKey, Lease> leases_;
  std::atomic<std::size_t> count_{0};  ///< leases_.size(), read without the lock
};

/// `id` with separators removed and hex letters lower-cased.
[[nodiscard]] std::string canonical_client_id(std::string_view id);

}  // namespace dh3::dds
