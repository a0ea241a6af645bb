// StandbyPresence: a standby's participant, its standby claim and its watch
// over the primary's liveliness.

#include "dh3/dds/standby_presence.hpp"

#include <spdlog/spdlog.h>

#include "conversions.hpp"
#include "dh3/contract/participant.hpp"
#include "dh3/contract/participant_setup.hpp"
#include "dh3/contract/peer_discovery_listener.hpp"
#include "lease_follower.hpp"
#include "owner_beacon.hpp"
#include "primary_watch.hpp"
#include "request_drain.hpp"
#include "service_endpoints.hpp"

namespace dh3::dds {

class StandbyPresence::Impl {
 public:
  explicit Impl(std::string name)
      : name_(std::move(name)),
        beacon_(new OwnerBeacon(SystemClock::instance())),
        listener_(claimant_callbacks(*beacon_)) {
    handover_.beacon.reset(beacon_);
  }
  ~Impl() {
    leases_.reset();
    if (handover_.beacon) handover_.beacon->stop();
    handover_.participant.reset();
  }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  Result<void, std::string> init(const ServiceOptions& options) {
    contract::ParticipantOptions participant = options.participant;
    // Not "dh3-service NAME": a client takes a participant of that name for
    // the service itself, before any of its samples arrive.
    participant.name = std::string(contract::kStandbyParticipantPrefix) + options.name;
    participant.cell = options.name;  // the partitions the service it becomes publishes in
    contract::SetupReport report;
    // The beacon exists before the participant: discovery may call the
    // listener before create() returns.
    auto made = contract::Participant::create(participant, report, &listener_);
    for (const auto& warning : report.warnings) spdlog::warn("{}", warning);
    for (const auto& note : report.notes) spdlog::info("{}", note);
    if (!made) return fail(std::move(made).error());
    handover_.participant = std::move(made).value();
    if (auto created = beacon_->create(*handover_.participant); !created) {
      return fail("cannot create " + created.error());
    }
    if (auto endpoints = make_endpoints(options); !endpoints) return endpoints;
    if (auto follower = LeaseFollower::create(*handover_.participant, options.name); follower) {
      leases_ = std::move(follower).value();
    } else {
      spdlog::warn("standby: cannot create {}: no lease survives a takeover", follower.error());
    }
    const msg::ServiceOwner self = own_claim(options.name, options.host, wall_clock_ns());
    watch_.emplace(contract::to_claim(self, handover_.participant->client_id()),
                   SystemClock::instance().now(), vacancy_wait_);
    return beacon_->stand_by(self);
  }

  std::optional<PrimaryLapse> lapse(TimePoint now, std::optional<TimePoint> buses_silent_at) {
    const OwnerView view = beacon_->read_table([this](const contract::OwnerTable& table) {
      return OwnerView{table.owner(name_), table.highest_epoch(name_), table.standbys(name_),
                       table.claim_awaited(name_)};
    });
    bool changed = false;
    auto lost = watch_->look(view, now, buses_silent_at, &changed);
    if (lost && lost->primary) primary_ = lost->primary->participant;
    if (changed) {
      spdlog::info("standby: service '{}' is served by {} (epoch {})", name_,
                   view.owner->describe(), view.owner->epoch);
    }
    return lost;
  }

  std::optional<contract::OwnerClaim> owner() const { return beacon_->owner(name_); }
  void set_vacancy_wait(std::optional<Duration> wait) { vacancy_wait_ = wait; }

  Handover hand_over() {
    if (leases_ && !primary_.empty()) handover_.leases = leases_->held_by_writer(primary_);
    leases_.reset();
    // Before the claim turns active: what arrives from now on is the new owner's.
    if (handover_.drains) handover_.drains->hold();
    return std::move(handover_);
  }

 private:
  /// The service's endpoints, made now so that every client matches them
  /// before a takeover; a standby whose permissions refuse them fails here,
  /// at its start, rather than at the takeover.
  Result<void, std::string> make_endpoints(const ServiceOptions& options) {
    auto& participant = *handover_.participant;
    handover_.drains = std::make_unique<RequestDrains>();
    handover_.endpoints = std::make_unique<ServiceEndpoints>();
    auto& drains = *handover_.drains;
    auto made = handover_.endpoints->create_writers(participant, {});
    if (made) {
      made = handover_.endpoints->create_readers(participant,
                                                 {&drains.commands, &drains.admin, &drains.groups});
    }
    if (!made) return fail(cannot_create(made.error(), options.participant, participant));
    return {};
  }

  std::string name_;
  /// The beacon (real time: it waits on DDS liveliness); handover_ owns it
  /// until the takeover, the service after it.
  OwnerBeacon* beacon_;
  /// Tells the beacon which participants are services or standbys, and
  /// which left: a standby judging its cell vacant awaits their claims.
  static contract::PeerDiscoveryListener::Callbacks claimant_callbacks(OwnerBeacon& beacon) {
    return {
        [&beacon](const std::string& participant, const std::string& name) {
          beacon.announced(participant, name);
        },
        [&beacon](const std::string& participant, bool /*dropped*/) { beacon.left(participant); },
        {}};
  }

  contract::PeerDiscoveryListener listener_;
  /// The participant, the beacon, the service's endpoints and their drains.
  Handover handover_;
  std::optional<Duration> vacancy_wait_;
  std::optional<PrimaryWatch> watch_;      ///< made once our claim is known
  std::unique_ptr<LeaseFollower> leases_;  ///< null if it could not be made
  std::string primary_;  ///< the participant of the primary whose loss lapse() confirmed
};

StandbyPresence::Handover::Handover() = default;
StandbyPresence::Handover::Handover(Handover&&) noexcept = default;
StandbyPresence::Handover::~Handover() = default;

StandbyPresence::Handover StandbyPresence::hand_over() {
  return impl_->hand_over();
}

StandbyPresence::StandbyPresence(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
StandbyPresence::~StandbyPresence() = default;

Result<std::unique_ptr<StandbyPresence>, std::string> StandbyPresence::create(
    const ServiceOptions& options, std::optional<Duration> vacancy_wait) {
  auto impl = std::make_unique<Impl>(options.name);
  impl->set_vacancy_wait(vacancy_wait);
  if (auto ok = impl->init(options); !ok) return fail(ok.error());
  return std::unique_ptr<StandbyPresence>(new StandbyPresence(std::move(impl)));
}

std::optional<PrimaryLapse> StandbyPresence::lapse(TimePoint now,
                                                   std::optional<TimePoint> buses_silent_at) {
  return impl_->lapse(now, buses_silent_at);
}

std::optional<contract::OwnerClaim> StandbyPresence::owner() const {
  return impl_->owner();
}

}  // namespace dh3::dds
