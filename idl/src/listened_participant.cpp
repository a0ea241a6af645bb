#include "dh3/contract/listened_participant.hpp"

#include <utility>

namespace dh3::contract {

ListenedParticipant::ListenedParticipant(PeerDiscoveryListener::Callbacks callbacks)
    : listener_(std::move(callbacks)) {}

ListenedParticipant::~ListenedParticipant() {
  leave();
}

Result<void, std::string> ListenedParticipant::join(const ParticipantOptions& options,
                                                    SetupReport& report) {
  auto made = Participant::create(options, report, &listener_);
  if (!made) return fail(std::move(made).error());
  participant_ = std::move(made).value();
  return {};
}

void ListenedParticipant::adopt(std::unique_ptr<Participant> participant) {
  participant_ = std::move(participant);
  participant_->participant().set_listener(&listener_, eprosima::fastdds::dds::StatusMask::none());
}

void ListenedParticipant::leave() {
  participant_.reset();  // its listener first, then everything it contains
}

}  // namespace dh3::contract
