#pragma once
// Whether other machines can reach a participant, read from the transports
// its QoS ends up with (the project's defaults, the interfaces given, or an XML
// profile's), so that a service open to a network without DDS Security says so
// at start (participant_setup.cpp).

#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>

namespace dh3::contract {

/// True unless every transport stays on this machine: shared memory, or UDP
/// or TCP with an interface whitelist of loopback addresses only. Fast DDS's
/// built-in transports, a socket transport without a whitelist (every
/// interface) or with another address in it, and a transport of a kind this
/// cannot judge all count as reachable.
[[nodiscard]] bool reaches_other_hosts(const eprosima::fastdds::dds::DomainParticipantQos& qos);

/// True if every transport is UDP (v4 or v6): then all the participant
/// receives from other processes waits, until read, in UDP sockets whose
/// queues the kernel can be asked about (the client's lapse judgement,
/// client/src/lapse_judge.hpp). Fast DDS's built-in transports (they add
/// shared memory), shared memory, TCP and unknown kinds are not.
[[nodiscard]] bool receives_over_udp_only(const eprosima::fastdds::dds::DomainParticipantQos& qos);

}  // namespace dh3::contract
