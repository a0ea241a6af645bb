#pragma once
// A bare Fast DDS participant on dh3's contract (IDL types, topic names, QoS
// and participant settings) for the benchmarks' raw DDS sides: the ping-pong
// floor of bench_round_trip and the command driver of bench_status_fanout.

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <string>

#include "dh3_idl/dh3PubSubTypes.h"
#include "dh3_participant.hpp"
#include "dh3_type_support.hpp"

namespace dh3::bench {

namespace fdds = eprosima::fastdds::dds;

/// A participant with the request and reply topics of the contract.
class RawParticipant {
 public:
  RawParticipant(int domain, const std::string& name, bool udp_only) {
    contract::TransportOptions transport;
    transport.udp_only = udp_only;
    participant_ = fdds::DomainParticipantFactory::get_instance()->create_participant(
        static_cast<fdds::DomainId_t>(domain), contract::participant_qos(name, transport), nullptr,
        fdds::StatusMask::none());
    if (participant_ == nullptr) return;
    const contract::Topics contract_topics = contract::create_topics(*participant_);
    request_topic = contract_topics.request;
    reply_topic = contract_topics.reply;
    publisher = participant_->create_publisher(fdds::PUBLISHER_QOS_DEFAULT);
    subscriber = participant_->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT);
  }
  ~RawParticipant() {
    if (participant_ == nullptr) return;
    participant_->delete_contained_entities();
    fdds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }
  RawParticipant(const RawParticipant&) = delete;
  RawParticipant& operator=(const RawParticipant&) = delete;

  [[nodiscard]] bool ok() const {
    return participant_ != nullptr && request_topic != nullptr && reply_topic != nullptr &&
           publisher != nullptr && subscriber != nullptr;
  }
  [[nodiscard]] std::string client_id() const {
    return contract::client_id_for(participant_->guid().guidPrefix);
  }

  fdds::Topic* request_topic = nullptr;
  fdds::Topic* reply_topic = nullptr;
  fdds::Publisher* publisher = nullptr;
  fdds::Subscriber* subscriber = nullptr;

 private:
  fdds::DomainParticipant* participant_ = nullptr;
};

}  // namespace dh3::bench
