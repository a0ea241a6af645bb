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
#include <memory>
#include <string>

#include "dh3/contract/dh3PubSubTypes.h"
#include "dh3/contract/participant_setup.hpp"

namespace dh3::bench {

namespace fdds = eprosima::fastdds::dds;

/// A participant with the request and reply topics of the contract.
class RawParticipant {
 public:
  RawParticipant(int domain, const std::string& name, bool udp_only) {
    contract::ParticipantOptions options;
    options.name = name;
    options.domain = domain;
    options.udp_only = udp_only;
    options.shared_memory = !udp_only;  // the "shm" rows: not the default
    contract::SetupReport report;
    auto created = contract::Participant::create(options, report);
    if (!created) return;
    participant_ = std::move(created).value();
    request_topic = participant_->topics().request;
    reply_topic = participant_->topics().reply;
    publisher = &participant_->publisher();
    subscriber = &participant_->subscriber();
  }
  /// The participant goes first: its readers' listeners may be the user's members.
  ~RawParticipant() { participant_.reset(); }
  RawParticipant(const RawParticipant&) = delete;
  RawParticipant& operator=(const RawParticipant&) = delete;

  [[nodiscard]] bool ok() const { return participant_ != nullptr; }
  [[nodiscard]] std::string client_id() const { return participant_->client_id(); }

  fdds::Topic* request_topic = nullptr;
  fdds::Topic* reply_topic = nullptr;
  fdds::Publisher* publisher = nullptr;
  fdds::Subscriber* subscriber = nullptr;

 private:
  std::unique_ptr<contract::Participant> participant_;
};

}  // namespace dh3::bench
