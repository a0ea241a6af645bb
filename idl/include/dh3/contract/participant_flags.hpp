#pragma once
// The command-line options with which a dh3 program joins the DDS domain
// (dh3-service, dh3ctl, dh3-web): their names, help and rules, written once.
// The help shows each option's default from the struct it fills, so a program
// whose default differs (the service's identity "service", a client's
// "operator") says its own.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace CLI {
class App;
class Option;
}  // namespace CLI

namespace dh3::contract {

inline constexpr std::string_view kDomainOption = "-d,--domain";
inline constexpr std::string_view kInterfaceOption = "-i,--interface";
inline constexpr std::string_view kUdpOnlyOption = "--udp-only";
inline constexpr std::string_view kSharedMemoryOption = "--shared-memory";
inline constexpr std::string_view kDiscoveryServerOption = "--discovery-server";
inline constexpr std::string_view kXmlOption = "--xml";
inline constexpr std::string_view kProfileOption = "--profile";
inline constexpr std::string_view kSecurityDirOption = "--security-dir";
inline constexpr std::string_view kSecurityIdentityOption = "--security-identity";

/// Where each option's value goes: the members of ParticipantOptions, or of
/// a struct with the same members (the client library's ClientOptions).
struct ParticipantFields {
  int& domain;
  std::vector<std::string>& interfaces;
  bool& udp_only;
  bool& shared_memory;
  std::vector<std::string>& discovery_servers;
  std::string& xml_profile_file;
  std::string& xml_profile;
  std::string& security_dir;
  std::string& security_identity;
};

template <class Options>
[[nodiscard]] ParticipantFields fields_of(Options& options) {
  return {options.domain,       options.interfaces,        options.udp_only,
          options.shared_memory, options.discovery_servers, options.xml_profile_file,
          options.xml_profile,  options.security_dir,      options.security_identity};
}

/// Who applies the rules (participant_checks.hpp): CLI11 as it parses, its
/// message naming the option, or the caller afterwards (dh3-service, whose
/// configuration keys hold the same rules for its file and command line).
enum class FlagChecks : std::uint8_t { on_parse, by_caller };

/// The options made, to ask which were given.
struct ParticipantOptionsGiven {
  CLI::Option* domain = nullptr;
  CLI::Option* interfaces = nullptr;
  CLI::Option* udp_only = nullptr;
  CLI::Option* shared_memory = nullptr;
  CLI::Option* discovery_servers = nullptr;
  CLI::Option* xml_profile_file = nullptr;
  CLI::Option* xml_profile = nullptr;
  CLI::Option* security_dir = nullptr;
  CLI::Option* security_identity = nullptr;
};

/// Adds --domain, --interface, --udp-only, --shared-memory,
/// --discovery-server, --xml, --profile, --security-dir and
/// --security-identity to `app`, each filling its field.
ParticipantOptionsGiven add_participant_options(CLI::App& app, const ParticipantFields& fields,
                                                FlagChecks checks);

}  // namespace dh3::contract
