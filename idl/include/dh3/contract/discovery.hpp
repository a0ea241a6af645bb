#pragma once
// How a participant discovers the others. With discovery servers
// (dh3/contract/discovery_servers.hpp: from configuration or ROS_DISCOVERY_SERVER) it
// becomes a discovery CLIENT of each. Without, simple discovery, in which a
// client of dh3 may hear services only (hear_services_only below).
//
//   auto servers = dh3::contract::choose_discovery_servers(config.discovery_servers);
//   if (!servers) return fail(servers.error());
//   auto qos = dh3::contract::participant_qos(name, transport);
//   dh3::contract::use_discovery_servers(qos, *servers);

#include <fastdds/rtps/common/Time_t.h>

#include <cstdint>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <vector>

#include "dh3/contract/discovery_servers.hpp"

namespace dh3::contract {

/// How often a participant that hears services only repeats its announcement:
/// the longest a service that starts after it waits to be found by it. Fast
/// DDS's default is 3 s; services receive one small sample a second per
/// client.
extern const eprosima::fastrtps::Duration_t announcement_period;

/// Makes the participant a discovery CLIENT of `servers`; with none it is left
/// alone (simple discovery). False only if Fast DDS has no prefix for an id,
/// which the parsers above already rule out.
[[nodiscard]] bool use_discovery_servers(eprosima::fastdds::dds::DomainParticipantQos& qos,
                                         const std::vector<DiscoveryServer>& servers);

/// How long a discovery server keeps a client of dh3 (the client library)
/// without hearing from it, instead of Fast DDS's 20 s. A service keeps the
/// 20 s: its lease is what tells the clients that a killed service is gone.
///
/// Why: a busy server loses clients. In a plant of 64 services and 130
/// clients started one every 0.5 s on two cores, the server pair declared 105
/// live clients gone within minutes (each service logged them as
/// having left the domain; no service was lost). Fast DDS 2.9 did not always
/// announce them to the services again (cell01's commander: never), and
/// then their commands went unanswered (8 of
/// 64 commanders failed their first command). With 60 s no client was lost
/// and no command failed (BENCHMARKS.md section 9).
///
/// The price: a client that dies without leaving the domain (SIGKILL, power
/// cut, cable) keeps the control leases it holds for up to 60 s instead of
/// 20, unless their own time to live ends first.
extern const eprosima::fastrtps::Duration_t client_lease_with_servers;

void use_client_lease_with_servers(eprosima::fastdds::dds::DomainParticipantQos& qos);

/// Simple discovery for a participant that needs services, not its fellow
/// clients: it announces itself to the domain's discovery multicast group as
/// usual, but does not listen to that group, so it learns of a participant
/// only when that one answers its announcement directly, as every participant
/// that listens to the group does (dh3-service among them). Clients thus
/// never discover each other.
///
/// Why: Fast DDS 2.9's simple discovery sends its announcement again to every
/// participant it knows each time it finds a new one, so N participants that
/// start together exchange on the order of N^3 messages: 128 dh3ctl started
/// at once on two cores spent 0.73 s of CPU each, 36 times what one alone
/// spends. Hearing services only makes it services x clients.
///
/// The price: a service that starts after the client is found when it hears
/// the client's next periodic announcement (`announcement_period`), not its
/// own first one.
void hear_services_only(eprosima::fastdds::dds::DomainParticipantQos& qos, std::uint32_t domain);

}  // namespace dh3::contract
