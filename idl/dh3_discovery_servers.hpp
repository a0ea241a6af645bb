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
// dh3_discovery.hpp applies a list to a participant's QoS.

#include <arpa/inet.h>
#include <netdb.h>
#include <sys/socket.h>

#include <cstdint>
#include <cstdlib>
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

  [[nodiscard]] std::string to_string() const {
    return address + ":" + std::to_string(port) + " (id " + std::to_string(id) + ")";
  }
  friend bool operator==(const DiscoveryServer&, const DiscoveryServer&) = default;
};

namespace detail {

inline std::string_view trim(std::string_view text) {
  const auto first = text.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t");
  return text.substr(first, last - first + 1);
}

/// A host name's first IPv4 address; empty if it has none.
inline std::string resolve_ipv4(const std::string& host) {
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_DGRAM;
  addrinfo* found = nullptr;
  if (getaddrinfo(host.c_str(), nullptr, &hints, &found) != 0 || found == nullptr) return {};
  char text[INET_ADDRSTRLEN] = {};
  const auto* address = reinterpret_cast<const sockaddr_in*>(found->ai_addr);
  const bool ok = inet_ntop(AF_INET, &address->sin_addr, text, sizeof text) != nullptr;
  freeaddrinfo(found);
  return ok ? std::string(text) : std::string();
}

/// Letters, digits, '-' and '.', not starting or ending with '.' or '-'.
inline bool is_host_name(std::string_view name) {
  if (name.empty() || name.size() > 253) return false;
  if (name.front() == '.' || name.front() == '-' || name.back() == '.' || name.back() == '-') {
    return false;
  }
  return name.find_first_not_of(
             "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-.") ==
         std::string_view::npos;
}

/// One "HOST[:PORT]" entry for server `id`, or what is wrong with it.
inline Result<DiscoveryServer, std::string> parse_server_entry(std::string_view entry, int id) {
  const std::string text(entry);
  const auto malformed = [&](const std::string& why) {
    return dh3::fail("discovery server '" + text + "': " + why);
  };
  if (id > kMaxDiscoveryServerId) {
    return malformed("more than " + std::to_string(kMaxDiscoveryServerId + 1) +
                     " server positions (ids 0-" + std::to_string(kMaxDiscoveryServerId) + ")");
  }
  std::string_view address = entry;
  std::uint16_t port = kDefaultDiscoveryServerPort;
  if (const auto colon = entry.rfind(':'); colon != std::string_view::npos) {
    address = entry.substr(0, colon);
    const auto digits = entry.substr(colon + 1);
    if (digits.empty() || digits.size() > 5 ||
        digits.find_first_not_of("0123456789") != std::string_view::npos) {
      return malformed("the port must be a number, 1-65535");
    }
    const long value = std::strtol(std::string(digits).c_str(), nullptr, 10);
    if (value < 1 || value > 65535) return malformed("the port must be a number, 1-65535");
    port = static_cast<std::uint16_t>(value);
  }
  std::string ipv4(address);
  in_addr parsed{};
  if (inet_pton(AF_INET, ipv4.c_str(), &parsed) != 1) {
    // Dotted digits that are no address are a typo, not a host name.
    if (!is_host_name(address) ||
        address.find_first_not_of("0123456789.") == std::string_view::npos) {
      return malformed("expected IPV4[:PORT] or HOST[:PORT], e.g. 192.168.1.10:11811");
    }
    ipv4 = resolve_ipv4(std::string(address));
    if (ipv4.empty()) return malformed("the host name has no IPv4 address");
  }
  return DiscoveryServer{id, ipv4, port};
}

}  // namespace detail

/// Servers, or what is wrong with the text they came from (naming the bad entry).
using DiscoveryServerList = Result<std::vector<DiscoveryServer>, std::string>;

/// Entries as a configuration or command line gives them: each "HOST[:PORT]",
/// the n-th is server id n; an empty entry skips that id.
[[nodiscard]] inline DiscoveryServerList discovery_servers_from_entries(
    const std::vector<std::string>& entries) {
  std::vector<DiscoveryServer> servers;
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const auto entry = detail::trim(entries[i]);
    if (entry.empty()) continue;
    auto server = detail::parse_server_entry(entry, static_cast<int>(i));
    if (!server) return dh3::fail(std::move(server).error());
    servers.push_back(std::move(server).value());
  }
  return servers;
}

/// ROS_DISCOVERY_SERVER syntax: entries separated by ';'.
[[nodiscard]] inline DiscoveryServerList parse_discovery_server_list(std::string_view text) {
  std::vector<std::string> entries;
  std::size_t start = 0;
  while (true) {
    const auto end = text.find(';', start);
    entries.emplace_back(text.substr(start, end - start));
    if (end == std::string_view::npos) break;
    start = end + 1;
  }
  return discovery_servers_from_entries(entries);
}

/// The servers ROS_DISCOVERY_SERVER names; an empty list when it is unset or blank.
[[nodiscard]] inline DiscoveryServerList discovery_servers_from_environment() {
  const char* value = std::getenv(kDiscoveryServerEnv);
  if (value == nullptr) return std::vector<DiscoveryServer>{};
  auto list = parse_discovery_server_list(value);
  if (!list) return dh3::fail(std::string(kDiscoveryServerEnv) + ": " + list.error());
  return list;
}

/// The configured servers if any are given, otherwise ROS_DISCOVERY_SERVER's.
[[nodiscard]] inline DiscoveryServerList choose_discovery_servers(
    const std::vector<std::string>& configured) {
  for (const auto& entry : configured) {
    if (!detail::trim(entry).empty()) return discovery_servers_from_entries(configured);
  }
  return discovery_servers_from_environment();
}

}  // namespace dh3::contract
