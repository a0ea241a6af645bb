// StandbyPresence: a standby's participant, its standby claim and its watch
// over the primary's liveliness.

#include "dh3/dds/standby_presence.hpp"

#include <spdlog/spdlog.h>

#include "conversions.hpp"
#include "dh3/contract/participant.hpp"
#include "dh3/contract/participant_setup.hpp"
#include "owner_beacon.hpp"
#include "primary_watch.hpp"

namespace dh3::dds {

class StandbyPresence::Impl {
 public:
  explicit Impl(std::string name) : name_(std::move(name)) {}
  ~Impl() {
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
    auto made = contract::Participant::create(participant, report);
    for (const auto& warning : report.warnings) spdlog::warn("{}", warning);
    for (const auto& note : report.notes) spdlog::info("{}", note);
    if (!made) return fail(std::move(made).error());
    handover_.participant = std::move(made).value();
    handover_.beacon = std::make_unique<OwnerBeacon>(SystemClock::instance());
    if (auto created = handover_.beacon->create(*handover_.participant); !created) {
      return fail("cannot create " + created.error());
    }
    return handover_.beacon->stand_by(own_claim(options.name, options.host, wall_clock_ns()));
  }

  std::optional<PrimaryLapse> lapse(TimePoint now) {
    const auto owner = handover_.beacon->owner(name_);
    bool changed = false;
    auto lost = watch_.look(owner, handover_.beacon->highest_epoch(name_), now, &changed);
    if (changed) {
      spdlog::info("standby: service '{}' is served by {} (epoch {})", name_, owner->describe(),
                   owner->epoch);
    }
    return lost;
  }

  std::optional<contract::OwnerClaim> owner() const { return handover_.beacon->owner(name_); }

  Handover hand_over() { return std::move(handover_); }

 private:
  std::string name_;
  /// The participant and its beacon (real time: it waits on DDS liveliness).
  Handover handover_;
  PrimaryWatch watch_;
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
    const ServiceOptions& options) {
  auto impl = std::make_unique<Impl>(options.name);
  if (auto ok = impl->init(options); !ok) return fail(ok.error());
  return std::unique_ptr<StandbyPresence>(new StandbyPresence(std::move(impl)));
}

std::optional<PrimaryLapse> StandbyPresence::lapse(TimePoint now) {
  return impl_->lapse(now);
}

std::optional<contract::OwnerClaim> StandbyPresence::owner() const {
  return impl_->owner();
}

}  // namespace dh3::dds
