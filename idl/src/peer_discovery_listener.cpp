#include "dh3/contract/peer_discovery_listener.hpp"

#include <utility>

#include "dh3/contract/participant.hpp"

namespace dh3::contract {

PeerDiscoveryListener::PeerDiscoveryListener(Callbacks callbacks)
    : callbacks_(std::move(callbacks)) {}

void PeerDiscoveryListener::on_participant_discovery(
    eprosima::fastdds::dds::DomainParticipant* /*participant*/,
    eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) {
  using Status = eprosima::fastrtps::rtps::ParticipantDiscoveryInfo;
  const bool joined = info.status == Status::DISCOVERED_PARTICIPANT;
  if ((joined || info.status == Status::CHANGED_QOS_PARTICIPANT) && callbacks_.described) {
    callbacks_.described(info.info);
  }
  const std::string participant = client_id_for(info.info.m_guid.guidPrefix);
  if (joined) {
    if (callbacks_.announced)
      callbacks_.announced(participant, info.info.m_participantName.to_string());
  } else if (info.status == Status::REMOVED_PARTICIPANT ||
             info.status == Status::DROPPED_PARTICIPANT) {
    if (callbacks_.left) callbacks_.left(participant, info.status == Status::DROPPED_PARTICIPANT);
  }
}

}  // namespace dh3::contract
