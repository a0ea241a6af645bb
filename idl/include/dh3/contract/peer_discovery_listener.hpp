#pragma once
// What a participant's discovery says about the other participants of its
// domain, in dh3's terms: a participant, named by its id (client_id_for),
// announced a name, or left. The service, its standby and the client library
// each act on the same two events; this is the one place that reads them out
// of Fast DDS's discovery statuses.
//
// The callbacks run on a Fast DDS thread, possibly before
// Participant::create() has returned: what they touch must exist by then.

#include <fastdds/rtps/builtin/data/ParticipantProxyData.h>

#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <functional>
#include <string>

namespace dh3::contract {

class PeerDiscoveryListener final : public eprosima::fastdds::dds::DomainParticipantListener {
 public:
  struct Callbacks {
    /// A participant joined the domain: its id and the name it announced.
    std::function<void(const std::string& participant, const std::string& name)> announced;
    /// It left: `dropped` when its lease expired rather than it saying goodbye.
    std::function<void(const std::string& participant, bool dropped)> left;
    /// Optional: its discovery data when it joined (before `announced`) or
    /// changed its QoS, for those that show more than its name.
    std::function<void(const eprosima::fastrtps::rtps::ParticipantProxyData& data)> described;
  };

  explicit PeerDiscoveryListener(Callbacks callbacks);

  void on_participant_discovery(eprosima::fastdds::dds::DomainParticipant* participant,
                                eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) override;

 private:
  Callbacks callbacks_;
};

}  // namespace dh3::contract
