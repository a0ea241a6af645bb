#include "dh3/contract/discovery_servers.hpp"

#include <arpa/inet.h>
#include <netdb.h>
#include <sys/socket.h>

#include <cstdlib>

#include "dh3/base/host_port.hpp"

namespace dh3::contract {

namespace {

std::string_view trim(std::string_view text) {
  const auto first = text.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t");
  return text.substr(first, last - first + 1);
}

/// A host name's first IPv4 address; empty if it has none.
std::string resolve_ipv4(const std::string& host) {
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
bool is_host_name(std::string_view name) {
  if (name.empty() || name.size() > 253) return false;
  if (name.front() == '.' || name.front() == '-' || name.back() == '.' || name.back() == '-') {
    return false;
  }
  return name.find_first_not_of(
             "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-.") ==
         std::string_view::npos;
}

constexpr std::string_view kExpected = "expected IPV4[:PORT] or HOST[:PORT], e.g. 192.168.1.10:11811";

/// One "HOST[:PORT]" entry for server `id`, or what is wrong with it.
Result<DiscoveryServer, std::string> parse_server_entry(std::string_view entry, int id) {
  const std::string text(entry);
  const auto malformed = [&](const std::string& why) {
    return dh3::fail("discovery server '" + text + "': " + why);
  };
  if (id > kMaxDiscoveryServerId) {
    return malformed("more than " + std::to_string(kMaxDiscoveryServerId + 1) +
                     " server positions (ids 0-" + std::to_string(kMaxDiscoveryServerId) + ")");
  }
  HostPortRules rules;
  rules.default_port = kDefaultDiscoveryServerPort;
  auto parsed = parse_host_port(entry, rules);
  if (!parsed) return malformed(parsed.error() + "; " + std::string(kExpected));
  const std::string_view host = parsed->host;
  std::string ipv4 = parsed->host;
  in_addr literal{};
  if (inet_pton(AF_INET, ipv4.c_str(), &literal) != 1) {
    // Dotted digits that are no address are a typo, not a host name.
    if (parsed->bracketed || !is_host_name(host) ||
        host.find_first_not_of("0123456789.") == std::string_view::npos) {
      return malformed(std::string(kExpected));
    }
    ipv4 = resolve_ipv4(parsed->host);
    if (ipv4.empty()) return malformed("the host name has no IPv4 address");
  }
  return DiscoveryServer{id, ipv4, parsed->port};
}

}  // namespace

std::string DiscoveryServer::to_string() const {
  return address + ":" + std::to_string(port) + " (id " + std::to_string(id) + ")";
}

DiscoveryServerList discovery_servers_from_entries(const std::vector<std::string>& entries) {
  std::vector<DiscoveryServer> servers;
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const auto entry = trim(entries[i]);
    if (entry.empty()) continue;
    auto server = parse_server_entry(entry, static_cast<int>(i));
    if (!server) return dh3::fail(std::move(server).error());
    servers.push_back(std::move(server).value());
  }
  return servers;
}

DiscoveryServerList parse_discovery_server_list(std::string_view text) {
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

DiscoveryServerList discovery_servers_from_environment() {
  const char* value = std::getenv(kDiscoveryServerEnv);
  if (value == nullptr) return std::vector<DiscoveryServer>{};
  auto list = parse_discovery_server_list(value);
  if (!list) return dh3::fail(std::string(kDiscoveryServerEnv) + ": " + list.error());
  return list;
}

DiscoveryServerList choose_discovery_servers(const std::vector<std::string>& configured) {
  for (const auto& entry : configured) {
    if (!trim(entry).empty()) return discovery_servers_from_entries(configured);
  }
  return discovery_servers_from_environment();
}

}  // namespace dh3::contract
