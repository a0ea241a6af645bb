#pragma once
// Applies a list of Fast DDS discovery servers (dh3_discovery_servers.hpp:
// which servers, from configuration or ROS_DISCOVERY_SERVER) to a
// participant's QoS: it becomes a discovery CLIENT of each.
//
//   auto servers = dh3::contract::choose_discovery_servers(config.discovery_servers);
//   if (!servers) return fail(servers.error());
//   auto qos = dh3::contract::participant_qos(name, transport);
//   dh3::contract::use_discovery_servers(qos, *servers);

#include <fastdds/rtps/attributes/ServerAttributes.h>
#include <fastdds/rtps/common/Locator.h>
#include <fastrtps/utils/IPLocator.h>

#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <vector>

#include "dh3_discovery_servers.hpp"

namespace dh3::contract {

/// Makes the participant a discovery CLIENT of `servers`; with none it is left
/// alone (simple discovery). False only if Fast DDS has no prefix for an id,
/// which the parsers above already rule out.
[[nodiscard]] inline bool use_discovery_servers(eprosima::fastdds::dds::DomainParticipantQos& qos,
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

}  // namespace dh3::contract
