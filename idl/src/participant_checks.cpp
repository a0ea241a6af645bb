#include "dh3/contract/participant_checks.hpp"

#include <arpa/inet.h>
#include <unistd.h>

#include <algorithm>

#include "dh3/contract/discovery_servers.hpp"
#include "dh3/contract/security_files.hpp"

namespace dh3::contract {

Checked check_domain(long long domain) {
  if (domain < 0 || domain > kMaxDomainId) {
    return fail("domain " + std::to_string(domain) + " is out of range (0-" +
                std::to_string(kMaxDomainId) + ")");
  }
  return {};
}

Checked check_interface(std::string_view address) {
  if (address == "*") return {};
  in_addr parsed{};
  if (inet_pton(AF_INET, std::string(address).c_str(), &parsed) == 1) return {};
  return fail("interface '" + std::string(address) + "' is not an IPv4 address (or \"*\" for all)");
}

Checked check_discovery_server(std::string_view entry) {
  // One entry on its own: its position (the server id) cannot be wrong here,
  // only its text; empty entries are allowed (they skip an id).
  auto list = discovery_servers_from_entries({std::string(entry)});
  if (!list) return fail(std::move(list).error());
  return {};
}

Checked check_readable_file(std::string_view what, const std::string& path) {
  if (path.empty()) return fail(std::string(what) + " is empty");
  if (::access(path.c_str(), R_OK) != 0) {
    return fail("cannot read the " + std::string(what) + " '" + path + "'");
  }
  return {};
}

// A plain name, so that it cannot point outside the security directory.
Checked check_identity(std::string_view identity) {
  if (identity.empty()) return fail(std::string("the security identity is empty"));
  if (identity == "." || identity == ".." ||
      identity.find_first_not_of(
          "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789-_.") !=
          std::string_view::npos) {
    return fail("security identity '" + std::string(identity) +
                "' is not a plain name (letters, digits, '-', '_', '.')");
  }
  return {};
}

Result<void, Misfit> check_participant(
    const ParticipantOptions& options,
    const std::function<std::string(std::string_view field)>& label) {
  const auto& interfaces = options.interfaces;
  if (interfaces.size() > 1 &&
      std::find(interfaces.begin(), interfaces.end(), "*") != interfaces.end()) {
    return fail(Misfit{"interfaces", "\"*\" (all interfaces) cannot be combined with addresses"});
  }
  if (options.udp_only && options.shared_memory) {
    return fail(Misfit{"shared_memory", "contradicts " + label("udp_only") + ": give one of them"});
  }
  if (!options.xml_profile.empty() && options.xml_profile_file.empty()) {
    return fail(Misfit{"xml_profile", "a profile needs " + label("xml_profile_file") +
                                          ", the file defining it"});
  }
  if (!options.security_dir.empty()) {
    auto readable = check_security_files(
        security_files_in(options.security_dir, options.security_identity));
    if (!readable) {
      return fail(Misfit{"security_dir", readable.error() + " (identity '" +
                                             options.security_identity + "' in '" +
                                             options.security_dir + "')"});
    }
  }
  return {};
}

}  // namespace dh3::contract
