#include "dh3/contract/discovery.hpp"

#include <fastdds/rtps/attributes/ServerAttributes.h>
#include <fastdds/rtps/common/Locator.h>
#include <fastrtps/utils/IPLocator.h>

namespace dh3::contract {

const eprosima::fastrtps::Duration_t announcement_period{1, 0};
const eprosima::fastrtps::Duration_t client_lease_with_servers{60, 0};

bool use_discovery_servers(eprosima::fastdds::dds::DomainParticipantQos& qos,
                           const std::vector<DiscoveryServer>& servers) {
  namespace rtps = eprosima::fastrtps::rtps;
  if (servers.empty()) return true;
  auto& discovery = qos.wire_protocol().builtin.discovery_config;
  discovery.discoveryProtocol = rtps::DiscoveryProtocol_t::CLIENT;
  discovery.m_DiscoveryServers.clear();
  for (const auto& server : servers) {
    rtps::RemoteServerAttributes remote;
    if (!rtps::get_server_client_default_guidPrefix(server.id, remote.guidPrefix)) return false;
    rtps::Locator_t locator;
    rtps::IPLocator::setIPv4(locator, server.address);
    locator.port = server.port;
    remote.metatrafficUnicastLocatorList.push_back(locator);
    discovery.m_DiscoveryServers.push_back(remote);
  }
  return true;
}

void use_client_lease_with_servers(eprosima::fastdds::dds::DomainParticipantQos& qos) {
  qos.wire_protocol().builtin.discovery_config.leaseDuration = client_lease_with_servers;
}

void hear_services_only(eprosima::fastdds::dds::DomainParticipantQos& qos, std::uint32_t domain) {
  namespace rtps = eprosima::fastrtps::rtps;
  auto& builtin = qos.wire_protocol().builtin;
  // A unicast locator of port 0 on any address: Fast DDS fills in the
  // participant's own metatraffic port and the whitelisted interfaces. With
  // it given, Fast DDS adds no multicast locator of its own.
  rtps::Locator_t unicast;
  unicast.kind = LOCATOR_KIND_UDPv4;
  builtin.metatrafficUnicastLocatorList.clear();
  builtin.metatrafficUnicastLocatorList.push_back(unicast);
  builtin.metatrafficMulticastLocatorList.clear();
  // Announcements still go to the group the services listen to.
  rtps::Locator_t group;
  group.kind = LOCATOR_KIND_UDPv4;
  rtps::IPLocator::setIPv4(group, 239, 255, 0, 1);
  group.port = qos.wire_protocol().port.getMulticastPort(domain);
  builtin.initialPeersList.clear();
  builtin.initialPeersList.push_back(group);
  builtin.discovery_config.leaseDuration_announcementperiod = announcement_period;
}

}  // namespace dh3::contract
