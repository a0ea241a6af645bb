#pragma once
// How every dh3 participant (service, client library, tests, benchmarks) sets
// up its Fast DDS transports, so they always find each other the same way.
//
// The default is loopback only: a service on a robot cell's controller that is
// not told which network to use stays on the machine. Give `interfaces` (the
// IPv4 addresses of the NICs to use, or "*" for all) to reach other hosts.
//
// UDP only unless `shared_memory` is asked for. Fast DDS 2.9 (Debian 12's
// libfastrtps2.9) has a shared-memory listener that stops receiving for good
// once its port holds a message from a process that has since exited: it
// opens the sender's segment before taking the message off the queue, the
// open fails, and it retries the same message forever (fixed upstream in
// Fast DDS 2.12.1, "SHM transport: ignore non-existing segment on pop"). Any
// dh3ctl that exits while the service, or another client, has not yet read
// what it sent can make that participant deaf (docs/operations.md, "Which
// transport setup when", gives the evidence, BENCHMARKS.md section 1 the round
// trip over both).

#include <fastdds/rtps/common/InstanceHandle.h>

#include <cstdint>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/rtps/common/GuidPrefix_t.hpp>
#include <string>
#include <vector>

namespace dh3::contract {

struct TransportOptions {
  /// IPv4 addresses of the interfaces to use; empty = loopback only; {"*"} = all.
  std::vector<std::string> interfaces;
  /// Also Fast DDS's shared-memory transport between processes on one host
  /// (see above for why it is off by default).
  bool shared_memory = false;
};

/// How many ports a participant tries for each of its receive locators.
inline constexpr std::uint32_t kPortTries = 250;

/// The QoS of a participant named `participant_name` with the project's
/// transports.
eprosima::fastdds::dds::DomainParticipantQos participant_qos(const std::string& participant_name,
                                                             const TransportOptions& options);

/// The client_id a Fast DDS participant puts in its CommandRequests: its GUID
/// prefix as 24 lowercase hex digits, no separators. The service ends a client's
/// leases when the participant with that prefix leaves the domain.
std::string client_id_for(const eprosima::fastrtps::rtps::GuidPrefix_t& prefix);

/// The client_id of the participant of a matched reader or writer, or of a
/// sample's writer (a match status's last handle, SampleInfo::publication_handle).
std::string client_id_for(const eprosima::fastrtps::rtps::InstanceHandle_t& handle);

}  // namespace dh3::contract
