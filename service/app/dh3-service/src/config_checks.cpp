#include "config_checks.hpp"

#include <arpa/inet.h>
#include <unistd.h>

#include <algorithm>
#include <array>

#include "dh3/bus/bus_spec.hpp"
#include "dh3/metrics/metrics_exporter.hpp"
#include "dh3/contract/discovery_servers.hpp"
#include "dh3/contract/dh3.h"
#include "dh3/contract/security_files.hpp"

namespace dh3::app {
namespace {

constexpr std::size_t kMaxNameLength = limits::MAX_NAME_LENGTH;
constexpr std::array<std::string_view, 7> kLogLevels{"trace", "debug",    "info", "warn",
                                                     "error", "critical", "off"};

Checked check_security(const std::string& dir, const std::string& identity) {
  auto readable = contract::check_security_files(contract::security_files_in(dir, identity));
  if (!readable) return fail(readable.error() + " (identity '" + identity + "' in '" + dir + "')");
  return {};
}

}  // namespace

Checked check_name(std::string_view what, std::string_view name) {
  if (name.empty()) return fail(std::string(what) + " is empty");
  if (name.size() > kMaxNameLength) {
    return fail(std::string(what) + " '" + std::string(name) + "' is longer than " +
                std::to_string(kMaxNameLength) + " characters");
  }
  return {};
}

Checked check_log_level(std::string_view level) {
  if (std::find(kLogLevels.begin(), kLogLevels.end(), level) != kLogLevels.end()) {
    return {};
  }
  return fail("log level '" + std::string(level) +
              "' is not one of trace, debug, info, warn, error, critical, off");
}

Checked check_spec(std::string_view spec) {
  auto parsed = bus::parse_bus_spec(spec);
  if (!parsed) return fail(parsed.error());
  return {};
}

Checked check_metrics_address(std::string_view address) {
  // Empty: not served (the command line's way to turn the file's off).
  if (address.empty()) return {};
  return metrics::check_listen_address(address);
}

Checked check_not_empty(std::string_view what, std::string_view text) {
  if (text.empty()) return fail(std::string(what) + " is empty");
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
  auto list = contract::discovery_servers_from_entries({std::string(entry)});
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

// The identity names a sub-directory of the security directory: a plain name,
// so that it cannot point elsewhere.
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
    const contract::ParticipantOptions& participant,
    const std::function<std::string(std::string_view key)>& label) {
  const auto& interfaces = participant.interfaces;
  if (interfaces.size() > 1 &&
      std::find(interfaces.begin(), interfaces.end(), "*") != interfaces.end()) {
    return fail(Misfit{"dds.interfaces", "\"*\" (all interfaces) cannot be combined with addresses"});
  }
  if (participant.udp_only && participant.shared_memory) {
    return fail(
        Misfit{"dds.shared_memory", "contradicts " + label("dds.udp_only") + ": give one of them"});
  }
  if (!participant.xml_profile.empty() && participant.xml_profile_file.empty()) {
    return fail(Misfit{"dds.xml_profile", "a profile needs " + label("dds.xml_profile_file") +
                                              ", the file defining it"});
  }
  if (!participant.security_dir.empty()) {
    if (auto checked = check_security(participant.security_dir, participant.security_identity);
        !checked) {
      return fail(Misfit{"dds.security.dir", checked.error()});
    }
  }
  return {};
}

}  // namespace dh3::app
