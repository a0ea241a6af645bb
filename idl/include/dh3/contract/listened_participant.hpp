#pragma once
// What the service and the client library both hold on the DDS side: a
// Participant (its topics, publisher and subscriber) with the
// PeerDiscoveryListener that reports who joins and leaves, kept in the order
// Fast DDS needs. The listener outlives the participant, and the participant
// goes with every reader and writer made on it before its owner's other
// listeners do. The endpoints each side makes on it stay that side's.

#include <memory>
#include <string>

#include "dh3/base/result.hpp"
#include "dh3/contract/participant_options.hpp"
#include "dh3/contract/participant_setup.hpp"
#include "dh3/contract/peer_discovery_listener.hpp"

namespace dh3::contract {

class ListenedParticipant {
 public:
  explicit ListenedParticipant(PeerDiscoveryListener::Callbacks callbacks);
  ~ListenedParticipant();
  ListenedParticipant(const ListenedParticipant&) = delete;
  ListenedParticipant& operator=(const ListenedParticipant&) = delete;

  /// Joins the domain with a participant made from `options`; the callbacks
  /// may run before this returns. Notes and warnings go to `report`.
  Result<void, std::string> join(const ParticipantOptions& options, SetupReport& report);
  /// Takes over a participant made elsewhere (a standby's): the participants
  /// discovered from now on are reported here; those it knew already are not.
  void adopt(std::unique_ptr<Participant> participant);
  /// Deletes the participant and all it contains; no callback runs after.
  void leave();

  [[nodiscard]] bool joined() const { return participant_ != nullptr; }
  /// The participant (joined()).
  [[nodiscard]] Participant& operator*() const { return *participant_; }
  [[nodiscard]] Participant* operator->() const { return participant_.get(); }

 private:
  PeerDiscoveryListener listener_;
  std::unique_ptr<Participant> participant_;  ///< after listener_: deleted before it
};

}  // namespace dh3::contract
