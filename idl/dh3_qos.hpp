#pragma once
// The QoS half of the contract: every participant (service, client library,
// tests, benchmarks) uses these for dh3's topics, so readers and writers always
// match. Participants of other DDS vendors must use the same policies
// (documented beside the topic names in dh3.idl).

#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>

namespace dh3::contract {

enum class TopicRole {
  hand_status,   ///< keyed per hand; late joiners get the last sample of each hand
  service_info,  ///< keyed per service; late joiners get it
  hand_event,    ///< a stream; only live subscribers get events
  request,       ///< commands from clients
  reply,         ///< answers from services
};

/// History depth for the streams (events, requests, replies).
inline constexpr int kStreamDepth = 64;

template <typename Qos>
inline Qos qos_for(TopicRole role) {
  namespace dds = eprosima::fastdds::dds;
  Qos qos;
  qos.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  qos.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  switch (role) {
    case TopicRole::hand_status:
    case TopicRole::service_info:
      qos.durability().kind = dds::TRANSIENT_LOCAL_DURABILITY_QOS;
      qos.history().depth = 1;
      break;
    case TopicRole::hand_event:
    case TopicRole::request:
    case TopicRole::reply:
      qos.durability().kind = dds::VOLATILE_DURABILITY_QOS;
      qos.history().depth = kStreamDepth;
      break;
  }
  return qos;
}

inline eprosima::fastdds::dds::DataWriterQos writer_qos(TopicRole role) {
  return qos_for<eprosima::fastdds::dds::DataWriterQos>(role);
}

inline eprosima::fastdds::dds::DataReaderQos reader_qos(TopicRole role) {
  return qos_for<eprosima::fastdds::dds::DataReaderQos>(role);
}

}  // namespace dh3::contract
