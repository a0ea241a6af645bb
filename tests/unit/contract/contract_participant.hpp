#pragma once
// A bare Fast DDS participant on dh3's topics for the contract tests: created
// from a given QoS, with the IDL types registered and the five topics made, so
// a test can try to create each writer and reader and watch them match.

#include <unistd.h>

#include <chrono>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <functional>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "dh3/contract/dh3.h"
#include "dh3/contract/dh3PubSubTypes.h"
#include "dh3/contract/participant.hpp"
#include "dh3/contract/qos.hpp"
#include "support/test_domain.hpp"

namespace dh3::test {

/// Generous: discovery and the security handshake on a loaded machine.
inline constexpr std::chrono::seconds kContractDeadline{30};

/// A domain per test process, so parallel tests (ctest -j) do not meet.
inline int contract_test_domain() {
  return test_domain();
}

/// Polls `condition` until it holds or `deadline` passes.
inline bool eventually(const std::function<bool()>& condition,
                       std::chrono::milliseconds deadline = kContractDeadline) {
  const auto end = std::chrono::steady_clock::now() + deadline;
  while (!condition()) {
    if (std::chrono::steady_clock::now() >= end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return true;
}

class ContractParticipant {
 public:
  ContractParticipant(int domain, const eprosima::fastdds::dds::DomainParticipantQos& qos) {
    namespace fdds = eprosima::fastdds::dds;
    participant_ = fdds::DomainParticipantFactory::get_instance()->create_participant(
        static_cast<fdds::DomainId_t>(domain), qos, nullptr, fdds::StatusMask::none());
    if (participant_ == nullptr) return;
    add_topic(topics::HAND_STATUS, new msg::HandStatusPubSubType(),
              contract::TopicRole::hand_status);
    add_topic(topics::HAND_EVENT, new msg::HandEventPubSubType(), contract::TopicRole::hand_event);
    add_topic(topics::SERVICE_INFO, new msg::ServiceInfoPubSubType(),
              contract::TopicRole::service_info);
    add_topic(topics::COMMAND_REQUEST, new msg::CommandRequestPubSubType(),
              contract::TopicRole::request);
    add_topic(topics::COMMAND_REPLY, new msg::CommandReplyPubSubType(), contract::TopicRole::reply);
    publisher_ = participant_->create_publisher(fdds::PUBLISHER_QOS_DEFAULT);
    subscriber_ = participant_->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT);
  }
  ~ContractParticipant() {
    if (participant_ == nullptr) return;
    participant_->delete_contained_entities();
    eprosima::fastdds::dds::DomainParticipantFactory::get_instance()->delete_participant(
        participant_);
  }
  ContractParticipant(const ContractParticipant&) = delete;
  ContractParticipant& operator=(const ContractParticipant&) = delete;

  [[nodiscard]] bool created() const {
    return participant_ != nullptr && publisher_ != nullptr && subscriber_ != nullptr;
  }

  /// nullptr when the participant may not publish the topic.
  eprosima::fastdds::dds::DataWriter* writer(const std::string& topic) {
    const auto& t = topics_.at(topic);
    return publisher_->create_datawriter(t.topic, contract::writer_qos(t.role));
  }
  /// nullptr when the participant may not subscribe to the topic.
  eprosima::fastdds::dds::DataReader* reader(const std::string& topic) {
    const auto& t = topics_.at(topic);
    return subscriber_->create_datareader(t.topic, contract::reader_qos(t.role));
  }

 private:
  struct TopicEntry {
    eprosima::fastdds::dds::Topic* topic = nullptr;
    contract::TopicRole role{};
  };

  void add_topic(const std::string& name, eprosima::fastdds::dds::TopicDataType* type,
                 contract::TopicRole role) {
    eprosima::fastdds::dds::TypeSupport support(type);
    support.register_type(participant_);
    topics_[name] =
        TopicEntry{participant_->create_topic(name, support.get_type_name(),
                                              eprosima::fastdds::dds::TOPIC_QOS_DEFAULT),
                   role};
  }

  eprosima::fastdds::dds::DomainParticipant* participant_ = nullptr;
  eprosima::fastdds::dds::Publisher* publisher_ = nullptr;
  eprosima::fastdds::dds::Subscriber* subscriber_ = nullptr;
  std::map<std::string, TopicEntry> topics_;
};

inline int matched(eprosima::fastdds::dds::DataWriter* writer) {
  eprosima::fastdds::dds::PublicationMatchedStatus status;
  writer->get_publication_matched_status(status);
  return status.current_count;
}

inline int matched(eprosima::fastdds::dds::DataReader* reader) {
  eprosima::fastdds::dds::SubscriptionMatchedStatus status;
  reader->get_subscription_matched_status(status);
  return status.current_count;
}

/// Takes every sample the reader holds; returns how many were valid.
template <typename T>
int take_all(eprosima::fastdds::dds::DataReader* reader, std::vector<T>& out) {
  int count = 0;
  T sample;
  eprosima::fastdds::dds::SampleInfo info;
  while (reader->take_next_sample(&sample, &info) ==
         eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data) continue;
    out.push_back(sample);
    ++count;
  }
  return count;
}

}  // namespace dh3::test
