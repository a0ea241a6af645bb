// PeerDiscoveryListener (idl/include/dh3/contract/peer_discovery_listener.hpp):
// Fast DDS's participant discovery statuses, as the service, its standby and
// the client library act on them.

#include <fastdds/rtps/participant/ParticipantDiscoveryInfo.h>
#include <gtest/gtest.h>

#include <fastdds/rtps/attributes/RTPSParticipantAllocationAttributes.hpp>
#include <string>
#include <vector>

#include "dh3/contract/peer_discovery_listener.hpp"

namespace dh3::contract {
namespace {

using Status = eprosima::fastrtps::rtps::ParticipantDiscoveryInfo;

struct Heard {
  std::vector<std::string> events;
  PeerDiscoveryListener listener{
      {[this](const std::string& participant, const std::string& name) {
         events.push_back("announced " + participant + " " + name);
       },
       [this](const std::string& participant, bool dropped) {
         events.push_back(std::string(dropped ? "dropped " : "left ") + participant);
       },
       [this](const eprosima::fastrtps::rtps::ParticipantProxyData& data) {
         events.push_back("described " + data.m_participantName.to_string());
       }}};

  void report(Status::DISCOVERY_STATUS status, const std::string& name) {
    eprosima::fastrtps::rtps::ParticipantProxyData data{
        eprosima::fastrtps::rtps::RTPSParticipantAllocationAttributes{}};
    for (std::size_t i = 0; i < eprosima::fastrtps::rtps::GuidPrefix_t::size; ++i) {
      data.m_guid.guidPrefix.value[i] = static_cast<eprosima::fastrtps::rtps::octet>(i);
    }
    data.m_participantName = name;
    Status info(data);
    info.status = status;
    listener.on_participant_discovery(nullptr, std::move(info));
  }
};

constexpr const char* kId = "000102030405060708090a0b";

TEST(PeerDiscoveryListener, AParticipantThatJoinsIsDescribedThenAnnouncedByItsId) {
  Heard heard;
  heard.report(Status::DISCOVERED_PARTICIPANT, "dh3-service left");
  EXPECT_EQ(heard.events,
            (std::vector<std::string>{"described dh3-service left",
                                      std::string("announced ") + kId + " dh3-service left"}));
}

TEST(PeerDiscoveryListener, AQosChangeIsDescribedButNotAnnouncedAgain) {
  Heard heard;
  heard.report(Status::CHANGED_QOS_PARTICIPANT, "dh3ctl");
  EXPECT_EQ(heard.events, (std::vector<std::string>{"described dh3ctl"}));
}

TEST(PeerDiscoveryListener, AParticipantLeavesOrIsDroppedByItsId) {
  Heard heard;
  heard.report(Status::REMOVED_PARTICIPANT, "dh3ctl");
  heard.report(Status::DROPPED_PARTICIPANT, "dh3ctl");
  EXPECT_EQ(heard.events,
            (std::vector<std::string>{std::string("left ") + kId, std::string("dropped ") + kId}));
}

TEST(PeerDiscoveryListener, CallbacksLeftEmptyAreSkipped) {
  PeerDiscoveryListener listener{{}};
  eprosima::fastrtps::rtps::ParticipantProxyData data{
      eprosima::fastrtps::rtps::RTPSParticipantAllocationAttributes{}};
  for (const auto status : {Status::DISCOVERED_PARTICIPANT, Status::CHANGED_QOS_PARTICIPANT,
                            Status::REMOVED_PARTICIPANT, Status::DROPPED_PARTICIPANT}) {
    Status info(data);
    info.status = status;
    listener.on_participant_discovery(nullptr, std::move(info));
  }
}

}  // namespace
}  // namespace dh3::contract
