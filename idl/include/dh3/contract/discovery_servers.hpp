#pragma once
// Fast DDS discovery servers for dh3 participants (service, client library,
// tools). Where multicast does not pass (routed subnets, VPNs, most container
// and cloud networks) every participant is a CLIENT of one or more servers
// (`fastdds discovery -i ID -l ADDRESS -p PORT`) and finds the others only
// through them; data then flows directly between the participants (unicast).
//
// Servers are named as in the ROS_DISCOVERY_SERVER convention, which Fast DDS
// itself follows: a list of "HOST[:PORT]" entries in which the n-th entry is
// the server started with `-i n`. Its GUID prefix is Fast DDS's default prefix
// for that id, so nothing but the address has to be configured. An empty entry
// skips an id (";10.0.0.2:11811" is server 1 alone); PORT defaults to 11811.
// HOST is an IPv4 address or a host name, resolved (IPv4) when the list is
// read, as Fast DDS does: service names in Compose or Kubernetes work.
//
// Which servers a participant uses: the configured ones (config key, command
// line) if any, otherwise ROS_DISCOVERY_SERVER if set, otherwise none (simple
// multicast discovery). choose_discovery_servers() implements that order so
// the service and the client behave alike.
//
// A client reaches its servers through its UDP transport: the transport's
// interfaces (dh3::contract::TransportOptions) must include one on the
// server's network; the loopback-only default reaches only a local server.
//
// This header has no Fast DDS in it (configuration code may use it);
// dh3/contract/discovery.hpp applies a list to a participant's QoS.

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "dh3/base/result.hpp"

namespace dh3::contract {

/// The port `fastdds discovery` listens on unless told otherwise.
inline constexpr std::uint16_t kDefaultDiscoveryServerPort = 11811;
/// Fast DDS has a default GUID prefix for server ids 0-255.
inline constexpr int kMaxDiscoveryServerId = 255;
/// The environment variable Fast DDS and ROS 2 read.
inline constexpr const char* kDiscoveryServerEnv = "ROS_DISCOVERY_SERVER";

struct DiscoveryServer {
  int id = 0;           ///< the server's `-i` id: its position in the list
  std::string address;  ///< IPv4, dotted quad (a host name is resolved when parsed)
  std::uint16_t port = kDefaultDiscoveryServerPort;

  /// "ADDRESS:PORT (id N)".
  [[nodiscard]] std::string to_string() const;
  friend bool operator==(const DiscoveryServer&, const DiscoveryServer&) = default;
};

/// Servers, or what is wrong with the text they came from (naming the bad entry).
using DiscoveryServerList = Result<std::vector<DiscoveryServer>, std::string>;

/// Entries as a configuration or command line gives them: each "HOST[:PORT]",
/// the n-th is server id n; an empty entry skips that id.
[[nodiscard]] DiscoveryServerList discovery_servers_from_entries(
    const std::vector<std::string>& entries);

/// ROS_DISCOVERY_SERVER syntax: entries separated by ';'.
[[nodiscard]] DiscoveryServerList parse_discovery_server_list(std::string_view text);

/// The servers ROS_DISCOVERY_SERVER names; an empty list when it is unset or blank.
[[nodiscard]] DiscoveryServerList discovery_servers_from_environment();

/// The configured servers if any are given, otherwise ROS_DISCOVERY_SERVER's.
[[nodiscard]] DiscoveryServerList choose_discovery_servers(
    const std::vector<std::string>& configured);

}  // namespace dh3::contract
