#pragma once
// Who owns a cell name: the rule every participant applies to the
// ServiceOwner samples and their writers' liveliness (dh3.idl, topic
// SERVICE_OWNER; docs/failover.md). Knows no Fast DDS, only the wire types: a
// participant is its GUID prefix in hex (client_id_for), so the rule runs the
// same in a service, a standby and a client, and in tests on a fake clock.
//
// Not thread-safe: each user keeps its table under its own lock.

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dh3/base/clock.hpp"
#include "dh3/contract/dh3.h"

namespace dh3::contract {

/// The liveliness of a service's owner writer (docs/failover.md says why
/// these numbers; contract/qos.hpp applies them). The writer offers, and every
/// reader requests, MANUAL_BY_TOPIC with this lease: Fast DDS 2.9.1 lets a
/// live AUTOMATIC or MANUAL_BY_PARTICIPANT writer of another participant keep
/// a dead one alive until the participant lease ends (eProsima/Fast-DDS
/// #4373); MANUAL_BY_TOPIC is checked per writer. Fast DDS reports a lapse
/// between lease - period and lease after the last assertion.
inline constexpr std::chrono::milliseconds kOwnerLease{700};
/// How often a service asserts it: six assertions in a row may be lost or
/// late (a 200 ms network stall, a service starved by busy loops or slowed by
/// sanitizers) before a reader declares the service dead.
inline constexpr std::chrono::milliseconds kOwnerAssertPeriod{100};
/// How long a client waits, after a lease lapsed, for the owner to assert
/// again before it believes the lapse: a client process stalled itself (32
/// clients starting in one process, sanitizers) may see the lease lapse before
/// it reads the assertions queued meanwhile. A death is then seen between
/// lease - period + this and lease + this after the last assertion.
inline constexpr std::chrono::milliseconds kOwnerLapseConfirm{150};
/// How long after its report a lapse must stand before a client that cannot
/// see its own receive queues (a transport other than UDP) ends the calls in
/// flight to that service SERVICE_LOST. One that can ends them with the
/// service's loss if it has read all it received, or once it caught up
/// (client/src/lapse_judge.hpp): 32 clients started together in one process
/// on a loaded 2-core machine saw lapses that the service overturned
/// 230-680 ms after Fast DDS reported them, and some for over 2 s, while
/// their sockets held the assertions unread (docs/failover.md).
inline constexpr std::chrono::milliseconds kOwnerLapseCallConfirm{5000};
/// How long a service listens before it serves: the owner lease (a service
/// killed just before has then been seen dead) and a second for discovery.
inline constexpr std::chrono::milliseconds kStartClaimWindow =
    kOwnerLease + std::chrono::seconds(1);

/// What a service's participant announces as its name before the cell name
/// ("dh3-service cell1"), so that others know a service of that name is
/// there before any of its samples arrive.
inline constexpr std::string_view kServiceParticipantPrefix = "dh3-service ";
/// What a standby's participant announces ("dh3-standby cell1"): never taken
/// for the service itself.
inline constexpr std::string_view kStandbyParticipantPrefix = "dh3-standby ";

/// The cell name a participant's announced name says it serves, if it is a service's.
std::optional<std::string> announced_service(std::string_view participant_name);

/// How much longer than the window a starting service waits for the claim of
/// a participant that announced itself as a service of its name: on a loaded
/// machine the claim sample may take longer than the window to arrive, and a
/// duplicate that served meanwhile would outrank the owner it missed.
inline constexpr std::chrono::milliseconds kStartClaimAwait{3000};

/// One service process's claim on a cell name, as its owner writer wrote it.
struct OwnerClaim {
  std::string participant;  ///< GUID prefix in hex
  std::string service;
  std::string host;
  std::int32_t pid = 0;
  std::uint64_t started_ns = 0;  ///< wall clock, ns since the epoch
  bool standby = false;
  std::uint64_t epoch = 0;

  /// "pid 4711 on host 'cellpc1' (participant 01f2...)", for error messages.
  [[nodiscard]] std::string describe() const;
};

/// A ServiceOwner sample in these terms, written by `participant`.
OwnerClaim to_claim(const msg::ServiceOwner& sample, const std::string& participant);

/// True if `a` rather than `b` owns their name when both are live and active:
/// the higher epoch (a takeover raised it), then the later start (a restart
/// supersedes what it replaced), then the higher participant prefix. A total
/// order on what both sides read, so two services that meet after a
/// partition agree on which one stops.
bool outranks(const OwnerClaim& a, const OwnerClaim& b);

/// Every claim seen, and which writers are alive now.
class OwnerTable {
 public:
  /// A claim sample arrived (a participant has one claim; a new one replaces it).
  void claim(OwnerClaim claim);
  /// The writer of `participant` asserted its liveliness (true) or missed its
  /// lease (false). May come before or after the claim sample.
  void set_alive(const std::string& participant, bool alive);
  /// Fast DDS changed the liveliness of the writer of `participant` by
  /// `change` (LivelinessChangedStatus::alive_count_change); returns whether
  /// it is alive now, for the caller to act on (set_alive() at once, or once
  /// a lapse is confirmed). Fast DDS 2.9
  /// reports a lapse from its event thread and the next assertion from a
  /// receive thread, each after releasing its lock, so the two may arrive
  /// in either order: taken by sign, an assertion that overtook its lapse
  /// would leave a live owner lapsed for good. A writer's changes alternate
  /// (+1, -1, +1, ...), so their sum says its state in any order: 1 alive.
  /// Never below 0: Fast DDS may also drop a report (see the client's
  /// ServiceTracker::note_status), and a lapse after a dropped first
  /// assertion must not leave the next assertion at 0.
  bool liveliness_changed(const std::string& participant, int change);
  /// The participant left the domain or its writer was deleted.
  void forget(const std::string& participant);
  /// `participant` announced itself in discovery as a service of `service`
  /// (its claim sample may follow later).
  void announced(const std::string& participant, std::string service);
  /// A participant announced as a service of `service` whose claim has not arrived.
  [[nodiscard]] bool claim_awaited(std::string_view service) const;

  /// The claim of `participant`, if its sample arrived.
  [[nodiscard]] std::optional<OwnerClaim> claim_of(const std::string& participant) const;
  /// Its liveliness was seen asserted and has not lapsed since.
  [[nodiscard]] bool alive(const std::string& participant) const;
  /// Fast DDS reported a change of its writer's liveliness at least once
  /// (liveliness_changed), since it was last forgotten.
  [[nodiscard]] bool liveliness_reported(const std::string& participant) const;
  /// Its liveliness was seen and then lapsed (killed, frozen or cut off).
  [[nodiscard]] bool lapsed(const std::string& participant) const;
  /// The owner of `service`: the highest-ranking active claim that has not
  /// lapsed. A claim whose liveliness is not seen yet counts: its sample came
  /// from a writer alive when it wrote it, and the first assertion may
  /// arrive after the sample (unknown is not dead).
  [[nodiscard]] std::optional<OwnerClaim> owner(std::string_view service) const;
  /// The standbys' claims on `service` that have not lapsed (unknown
  /// liveliness counts, as for owner()).
  [[nodiscard]] std::vector<OwnerClaim> standbys(std::string_view service) const;
  /// The highest epoch any claim on `service` carried, live or not (0: none).
  [[nodiscard]] std::uint64_t highest_epoch(std::string_view service) const;

 private:
  enum class Liveliness : std::uint8_t { unknown, alive, lapsed };
  /// What is known of one participant, from discovery and the owner topic.
  struct Entry {
    OwnerClaim claim;
    bool has_claim = false;
    Liveliness liveliness = Liveliness::unknown;
    int liveliness_sum = 0;  ///< of the changes Fast DDS reported, in whatever order
    bool liveliness_reported = false;
    /// The service it announced itself as in discovery, if it did.
    std::optional<std::string> announced_service;
  };
  std::map<std::string, Entry> entries_;  ///< by participant
};

/// A service's decision at start: it serves only once it has listened for a
/// while without meeting a live active owner of its name. `window` must
/// exceed the owner lease (a service killed just before is then seen dead)
/// and the time discovery takes to find the owner.
class StartClaim {
 public:
  enum class Verdict : std::uint8_t { wait, serve, refuse };

  StartClaim(std::string service, std::string self, Duration window, const Clock& clock);

  /// What to do now, given what `table` holds: refuse as soon as a live
  /// active owner of the name (not ourselves) is known, serve once the window
  /// has passed without one, and without a service of the name announced
  /// whose claim is still awaited (kStartClaimAwait at most).
  [[nodiscard]] Verdict decide(const OwnerTable& table);
  /// The owner that made decide() refuse.
  [[nodiscard]] const std::optional<OwnerClaim>& other() const { return other_; }
  /// The epoch to claim when serving: above every claim on the name seen.
  [[nodiscard]] std::uint64_t epoch(const OwnerTable& table) const;
  [[nodiscard]] TimePoint deadline() const { return deadline_; }

 private:
  std::string service_;
  std::string self_;
  TimePoint deadline_;
  const Clock& clock_;
  std::optional<OwnerClaim> other_;
};

}  // namespace dh3::contract
