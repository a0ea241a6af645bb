#pragma once
// A standby service's presence on DDS before it serves: its own participant
// with the owner writer and reader (owner_beacon.hpp), its claim written with
// the standby role (it never owns the name, so no client sends it requests or
// shows it as the service), and the primary's liveliness watched as every
// client watches it (docs/failover.md). It writes nothing else: no status,
// event, info or reply.
//
// The primary is lost when the owner of the name, once seen, has had no live
// active claimant for contract::kOwnerLapseConfirm, or sooner once the
// buses confirm it: its liveliness lapsed (killed, frozen, cut off) or its
// owner writer left (a clean stop). A lapse overturned before it is
// confirmed (a frozen owner asserting again) is forgotten.
// Given a vacancy wait, a cell that no owner served by then is vacant
// (primary_watch.hpp says when, and which of several standbys takes it).
//
// It reads the lease topic as well (lease_follower.hpp): at the takeover the
// leases the primary granted are handed to the service with the rest.
//
// It makes the service's endpoints as well (its writers, and request readers
// that drop every request until the takeover), and writes nothing with them.
// At the takeover the service is made on the same participant and endpoints
// (Service::take_over): every client has discovered them and matched them
// already, so the claim that turns active, the one they watch, is all a
// client needs to send its calls to the new owner.
//
// Threads: Fast DDS listener threads and the beacon's thread inside; lapse()
// from one thread.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "dh3/base/clock.hpp"
#include "dh3/base/result.hpp"
#include "dh3/contract/ownership.hpp"
#include "dh3/dds/service.hpp"

namespace dh3::contract {
class Participant;
}  // namespace dh3::contract

namespace dh3::dds {

class OwnerBeacon;
struct HandedLease;
struct ServiceEndpoints;
struct RequestDrains;

/// The primary's loss, as a standby confirmed it, or the cell's vacancy.
struct PrimaryLapse {
  /// The owner last seen; nullopt: none was ever seen (the cell is vacant).
  std::optional<contract::OwnerClaim> primary;
  TimePoint since{};        ///< when it was first seen without a live owner
  std::uint64_t epoch = 0;  ///< the highest epoch claimed on the name
};

class StandbyPresence {
 public:
  /// Joins the domain as `options` say (name, participant, host) and writes
  /// the standby's claim; fails with a message if DDS cannot be set up.
  /// `vacancy_wait`: how long a cell without an owner may stay so before
  /// this standby takes it; nullopt: only an owner seen and lost hands it over.
  [[nodiscard]] static Result<std::unique_ptr<StandbyPresence>, std::string> create(
      const ServiceOptions& options, std::optional<Duration> vacancy_wait = std::nullopt);
  ~StandbyPresence();
  StandbyPresence(const StandbyPresence&) = delete;
  StandbyPresence& operator=(const StandbyPresence&) = delete;

  /// The primary's confirmed loss at `now`, once it stands, or the cell's
  /// vacancy; nullopt while an owner lives, before either is due, or while a
  /// standby senior to this one is there to take the cell.
  /// `buses_silent_at`: the last time a read of every bus found it silent
  /// (StandbyWatch::silent_at); such a read after the lapse began confirms
  /// it without the wait.
  [[nodiscard]] std::optional<PrimaryLapse> lapse(
      TimePoint now, std::optional<TimePoint> buses_silent_at = std::nullopt);
  /// The owner of the name now (for logging who the standby watches).
  [[nodiscard]] std::optional<contract::OwnerClaim> owner() const;

  /// What the service that takes over is made on: Service::create takes it
  /// (once); the presence is empty after it.
  struct Handover {
    /// What the request readers tell until the service serves them; first,
    /// so that it outlives the participant whose readers use it.
    std::unique_ptr<RequestDrains> drains;
    std::unique_ptr<contract::Participant> participant;
    std::unique_ptr<OwnerBeacon> beacon;
    /// Made on the participant; what their request readers receive from the
    /// handover on is kept by the drains, for the service to serve.
    std::unique_ptr<ServiceEndpoints> endpoints;
    /// The leases the primary it took over from last said it granted, with
    /// their time left (none for a vacant cell).
    std::vector<HandedLease> leases;
    Handover();
    Handover(Handover&&) noexcept;
    ~Handover();
  };
  [[nodiscard]] Handover hand_over();

 private:
  class Impl;
  explicit StandbyPresence(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace dh3::dds
