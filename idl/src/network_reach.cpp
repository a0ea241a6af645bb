#include "dh3/contract/network_reach.hpp"

#include <fastdds/rtps/transport/SocketTransportDescriptor.h>
#include <fastdds/rtps/transport/UDPTransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>

#include <algorithm>

#include "dh3/base/host_port.hpp"

namespace dh3::contract {

bool reaches_other_hosts(const eprosima::fastdds::dds::DomainParticipantQos& qos) {
  namespace rtps = eprosima::fastdds::rtps;
  const auto& transport = qos.transport();
  if (transport.use_builtin_transports) return true;  // UDPv4 on every interface
  return std::any_of(
      transport.user_transports.begin(), transport.user_transports.end(),
      [](const std::shared_ptr<rtps::TransportDescriptorInterface>& descriptor) {
        if (dynamic_cast<const rtps::SharedMemTransportDescriptor*>(descriptor.get()) != nullptr) {
          return false;
        }
        const auto* socket = dynamic_cast<const rtps::SocketTransportDescriptor*>(descriptor.get());
        if (socket == nullptr) return true;
        const auto& allowed = socket->interfaceWhiteList;
        return allowed.empty() ||
               !std::all_of(allowed.begin(), allowed.end(),
                            [](const std::string& address) { return is_loopback_host(address); });
      });
}

bool receives_over_udp_only(const eprosima::fastdds::dds::DomainParticipantQos& qos) {
  namespace rtps = eprosima::fastdds::rtps;
  const auto& transport = qos.transport();
  if (transport.use_builtin_transports || transport.user_transports.empty()) return false;
  return std::all_of(transport.user_transports.begin(), transport.user_transports.end(),
                     [](const std::shared_ptr<rtps::TransportDescriptorInterface>& descriptor) {
                       return dynamic_cast<const rtps::UDPTransportDescriptor*>(
                                  descriptor.get()) != nullptr;
                     });
}

}  // namespace dh3::contract
