#include "dh3/contract/participant.hpp"

#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>

#include <cstddef>
#include <memory>

namespace dh3::contract {

eprosima::fastdds::dds::DomainParticipantQos participant_qos(const std::string& participant_name,
                                                             const TransportOptions& options) {
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

std::string client_id_for(const eprosima::fastrtps::rtps::GuidPrefix_t& prefix) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string id;
  id.reserve(2 * eprosima::fastrtps::rtps::GuidPrefix_t::size);
  for (std::size_t i = 0; i < eprosima::fastrtps::rtps::GuidPrefix_t::size; ++i) {
    id.push_back(kDigits[prefix.value[i] >> 4]);
    id.push_back(kDigits[prefix.value[i] & 0x0F]);
  }
  return id;
}

std::string client_id_for(const eprosima::fastrtps::rtps::InstanceHandle_t& handle) {
  return client_id_for(eprosima::fastrtps::rtps::iHandle2GUID(handle).guidPrefix);
}

}  // namespace dh3::contract
