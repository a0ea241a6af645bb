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

#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/rtps/common/GuidPrefix_t.hpp>
#include <fastdds/rtps/common/InstanceHandle.h>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>
#include <cstddef>
#include <cstdint>
#include <memory>
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

inline eprosima::fastdds::dds::DomainParticipantQos participant_qos(
    const std::string& participant_name, const TransportOptions& options) {
  // Aliases, not a using-directive: Fast DDS also declares a global ::dds
  // namespace (fastdds/dds/topic/Topic.hpp), which would make "dds::" ambiguous.
  namespace dds = eprosima::fastdds::dds;
  namespace rtps = eprosima::fastdds::rtps;
  dds::DomainParticipantQos qos;
  qos.name(participant_name);
  auto& transport = qos.transport();
  transport.use_builtin_transports = false;

  auto udp = std::make_shared<rtps::UDPv4TransportDescriptor>();
  const bool all = options.interfaces.size() == 1 && options.interfaces.front() == "*";
  if (!all) {
    udp->interfaceWhiteList = options.interfaces;
    if (udp->interfaceWhiteList.empty()) udp->interfaceWhiteList.push_back("127.0.0.1");
  }
  transport.user_transports.push_back(udp);
  // A participant whose port is taken tries the next one, 2 further on, this
  // many times: Fast DDS's 100 leaves the 101st participant of a domain on a
  // host without a unicast port (128 dh3ctl at once: the last ones never found
  // the service). Past about 120 the ports reach into the next
  // domain id's range, which a host running that many participants should
  // leave unused.
  qos.wire_protocol().builtin.mutation_tries = kPortTries;
  if (options.shared_memory) {
    transport.user_transports.push_back(std::make_shared<rtps::SharedMemTransportDescriptor>());
  }
  return qos;
}

/// The client_id a Fast DDS participant puts in its CommandRequests: its GUID
/// prefix as 24 lowercase hex digits, no separators. The service ends a client's
/// leases when the participant with that prefix leaves the domain.
inline std::string client_id_for(const eprosima::fastrtps::rtps::GuidPrefix_t& prefix) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string id;
  id.reserve(2 * eprosima::fastrtps::rtps::GuidPrefix_t::size);
  for (std::size_t i = 0; i < eprosima::fastrtps::rtps::GuidPrefix_t::size; ++i) {
    id.push_back(kDigits[prefix.value[i] >> 4]);
    id.push_back(kDigits[prefix.value[i] & 0x0F]);
  }
  return id;
}

/// The client_id of the participant of a matched reader or writer, or of a
/// sample's writer (a match status's last handle, SampleInfo::publication_handle).
inline std::string client_id_for(const eprosima::fastrtps::rtps::InstanceHandle_t& handle) {
  return client_id_for(eprosima::fastrtps::rtps::iHandle2GUID(handle).guidPrefix);
}

}  // namespace dh3::contract
