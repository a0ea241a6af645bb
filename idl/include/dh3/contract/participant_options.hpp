#pragma once
// Everything a dh3 participant (service, client library, test clients,
// benchmarks) is told about where and how it talks, in one struct. No Fast
// DDS here, so configuration code can fill it without the middleware;
// dh3/contract/participant_setup.hpp turns it into a participant.

#include <string>
#include <vector>

namespace dh3::contract {

struct ParticipantOptions {
  /// The DDS participant's name (seen by tools that list participants), used
  /// unless an XML profile names the participant.
  std::string name = "dh3";
  /// DDS domain id, 0-232.
  int domain = 0;
  /// A service's name: its writers publish in its cell's partition too
  /// (dh3/contract/cell_partition.hpp). Empty for clients.
  std::string cell;
  /// IPv4 addresses of the interfaces to use; empty = loopback only; {"*"} = all.
  std::vector<std::string> interfaces;
  /// UDP only: the default (dh3/contract/participant.hpp says why). Kept so that
  /// configurations and command lines that ask for it keep working; it
  /// contradicts shared_memory.
  bool udp_only = false;
  /// Also the shared-memory transport between processes on one host. Needs a
  /// Fast DDS with the listener fix of 2.12.1 (dh3/contract/participant.hpp).
  bool shared_memory = false;
  /// A participant of the client library, not a service (which leaves it
  /// off). With simple discovery it finds services but not fellow clients
  /// (dh3/contract/discovery.hpp, hear_services_only); with discovery servers its
  /// lease is longer (client_lease_with_servers).
  bool is_client = false;
  /// Fast DDS discovery servers as "HOST[:PORT]" (dh3/contract/discovery_servers.hpp);
  /// empty: ROS_DISCOVERY_SERVER's if set, unless an XML profile decides.
  std::vector<std::string> discovery_servers;
  /// A Fast DDS XML profiles file: the participant QoS comes from its profile
  /// `xml_profile` (or its default profile) instead of interfaces, udp_only and shared_memory.
  std::string xml_profile_file;
  std::string xml_profile;
  /// DDS Security with the credentials of `security_identity` in this
  /// directory (dh3/contract/security_files.hpp); empty: no security (unless the XML
  /// profile enables it).
  std::string security_dir;
  std::string security_identity;
};

/// A ParticipantOptions with the members it shares with `options` (the
/// client library's ClientOptions): all but name, cell and is_client, which
/// keep their defaults.
template <class Options>
[[nodiscard]] ParticipantOptions participant_options_of(const Options& options) {
  ParticipantOptions participant;
  participant.domain = options.domain;
  participant.interfaces = options.interfaces;
  participant.udp_only = options.udp_only;
  participant.shared_memory = options.shared_memory;
  participant.discovery_servers = options.discovery_servers;
  participant.xml_profile_file = options.xml_profile_file;
  participant.xml_profile = options.xml_profile;
  participant.security_dir = options.security_dir;
  participant.security_identity = options.security_identity;
  return participant;
}

}  // namespace dh3::contract
