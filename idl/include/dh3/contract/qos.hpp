#pragma once
// The QoS half of the contract: every participant (service, client library,
// tests, benchmarks) uses these for dh3's topics, so readers and writers always
// match. Participants of other DDS vendors must use the same policies
// (documented beside the topic names in dh3.idl).

#include <cstdint>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>

namespace dh3::contract {

enum class TopicRole {
  hand_status,   ///< keyed per hand; late joiners get the last sample of each hand
  service_info,  ///< keyed per service; late joiners get it
  hand_event,    ///< a stream; only live subscribers get events
  request,       ///< commands from clients
  reply,         ///< answers from services
  service_owner, ///< who serves a cell name, kept alive by liveliness (ownership.hpp)
  hand_lease,    ///< the owner's lease of each hand, for its standby; as hand_status
};

/// History depth for the streams (events, requests, replies).
inline constexpr int kStreamDepth = 64;

/// Heartbeat period of every reliable writer. A reader acknowledges, or asks
/// for what it missed, when a heartbeat comes; with Fast DDS's 3 s default a
/// lost sample costs seconds, and a writer waiting for acknowledgments before
/// it leaves (orderly shutdown) waits that long. Not part of matching.
inline constexpr std::uint32_t kHeartbeatPeriodNs = 100'000'000;

/// The most hands a status reader keeps (64 services of 256 hands): what any
/// participant, a spoofer too, can make a reader hold is bounded.
inline constexpr std::int32_t kMaxStatusKeys = 16384;

/// The QoS of dh3's writers and readers of a topic in `role`.
eprosima::fastdds::dds::DataWriterQos writer_qos(TopicRole role);
eprosima::fastdds::dds::DataReaderQos reader_qos(TopicRole role);

}  // namespace dh3::contract
