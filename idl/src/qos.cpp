#include "dh3/contract/qos.hpp"

#include "dh3/contract/ownership.hpp"

namespace dh3::contract {

namespace {

template <typename Qos>
Qos qos_for(TopicRole role) {
  namespace dds = eprosima::fastdds::dds;
  Qos qos;
  qos.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  qos.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  switch (role) {
    case TopicRole::service_owner:
      qos.liveliness().kind = dds::MANUAL_BY_TOPIC_LIVELINESS_QOS;
      qos.liveliness().lease_duration = eprosima::fastrtps::Duration_t(
          0, static_cast<std::uint32_t>(std::chrono::nanoseconds(kOwnerLease).count()));
      [[fallthrough]];
    case TopicRole::hand_status:
    case TopicRole::service_info:
    case TopicRole::hand_lease:
      qos.durability().kind = dds::TRANSIENT_LOCAL_DURABILITY_QOS;
      qos.history().depth = 1;
      // Fast DDS keeps at most 10 instances (keys) per writer and reader by
      // default: a service with more hands could not publish the 11th hand's
      // status, nor a client hold it. No limit (0, which Fast DDS accepts only
      // with max_samples 0 too); depth 1 bounds each hand's samples.
      qos.resource_limits().max_instances = 0;
      qos.resource_limits().max_samples = 0;
      break;
    case TopicRole::hand_event:
    case TopicRole::request:
      qos.durability().kind = dds::VOLATILE_DURABILITY_QOS;
      qos.history().depth = kStreamDepth;
      break;
    case TopicRole::reply:
      // A client may send its request as soon as its request writer matched
      // the service, before the service's reply writer has discovered the
      // client's reply reader; a volatile reply written in that window would
      // be lost. Kept replies reach a TRANSIENT_LOCAL reader (another
      // vendor's client) when it matches; clients take only replies carrying
      // their own client_id, which the writer filters for them
      // (dh3/contract/reply_filter.hpp). dh3's own client reads VOLATILE, so that it
      // is sent none of the replies kept for others, and dh3-service holds a
      // reply to it until its reader matched (service/dds ReplyGate).
      qos.durability().kind = dds::TRANSIENT_LOCAL_DURABILITY_QOS;
      qos.history().depth = kStreamDepth;
      break;
  }
  return qos;
}

}  // namespace

eprosima::fastdds::dds::DataWriterQos writer_qos(TopicRole role) {
  auto qos = qos_for<eprosima::fastdds::dds::DataWriterQos>(role);
  qos.reliable_writer_qos().times.heartbeatPeriod =
      eprosima::fastrtps::Duration_t(0, kHeartbeatPeriodNs);
  // The writers that filter for their readers (replies by client, statuses,
  // events and service info by followed cell) do so for any number of
  // readers: Fast DDS filters for 32 by default and sends the 33rd reader
  // and later every sample (README "Scaling to a plant"). Each filter costs
  // its evaluation per sample and 16 bytes of signature in each sample sent.
  if (role != TopicRole::request) {
    qos.writer_resource_limits().reader_filters_allocation =
        eprosima::fastrtps::ResourceLimitedContainerConfig::dynamic_allocation_configuration();
  }
  return qos;
}

eprosima::fastdds::dds::DataReaderQos reader_qos(TopicRole role) {
  auto qos = qos_for<eprosima::fastdds::dds::DataReaderQos>(role);
  if (role == TopicRole::hand_status) {
    qos.resource_limits().max_instances = kMaxStatusKeys;
    qos.resource_limits().max_samples_per_instance = 1;
    qos.resource_limits().max_samples = kMaxStatusKeys;
  }
  return qos;
}

}  // namespace dh3::contract
