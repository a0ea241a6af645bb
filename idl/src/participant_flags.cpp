#include "dh3/contract/participant_flags.hpp"

#include <CLI/CLI.hpp>
#include <functional>

#include "dh3/contract/participant_checks.hpp"

namespace dh3::contract {
namespace {

/// A rule as CLI11 runs it: "" for a good value, else why not.
CLI::Validator rule(std::function<Checked(const std::string&)> check) {
  return CLI::Validator(
      [check = std::move(check)](std::string& value) {
        auto checked = check(value);
        return checked ? std::string() : checked.error();
      },
      "");
}

std::string with_default(std::string help, const std::string& value) {
  if (!value.empty()) help += " (default " + value + ")";
  return help;
}

}  // namespace

ParticipantOptionsGiven add_participant_options(CLI::App& app, const ParticipantFields& fields,
                                                FlagChecks checks) {
  const bool on_parse = checks == FlagChecks::on_parse;
  const auto checked = [on_parse](CLI::Option* option, CLI::Validator validator) {
    if (on_parse) option->check(std::move(validator));
    return option;
  };
  ParticipantOptionsGiven given;
  given.domain = checked(
      app.add_option(std::string(kDomainOption), fields.domain,
                     with_default("DDS domain id, 0-" + std::to_string(kMaxDomainId),
                                  std::to_string(fields.domain))),
      rule([](const std::string& value) {
        long long domain = 0;
        // Not a number: CLI11's conversion says so.
        if (std::sscanf(value.c_str(), "%lld", &domain) != 1) return Checked{};
        return check_domain(domain);
      }));
  // One value per option: a stray word is an error, not a second address.
  given.interfaces = checked(app.add_option(std::string(kInterfaceOption), fields.interfaces,
                                            "IPv4 address of a network interface for DDS "
                                            "(repeatable), or * for all; default loopback only"),
                             rule([](const std::string& v) { return check_interface(v); }));
  given.interfaces->allow_extra_args(false);
  given.udp_only = app.add_flag(std::string(kUdpOnlyOption), fields.udp_only,
                                "UDP only, no shared memory (the default)");
  given.shared_memory =
      app.add_flag(std::string(kSharedMemoryOption), fields.shared_memory,
                   "also Fast DDS's shared-memory transport on this host (needs Fast DDS 2.12.1 "
                   "or later: 2.9's listener can go deaf after a peer exits)");
  given.discovery_servers = checked(
      app.add_option(std::string(kDiscoveryServerOption), fields.discovery_servers,
                     "a Fast DDS discovery server as HOST[:PORT] (repeatable; the n-th is the "
                     "server with id n); default: ROS_DISCOVERY_SERVER if set, else multicast"),
      rule([](const std::string& v) { return check_discovery_server(v); }));
  given.discovery_servers->allow_extra_args(false);
  given.xml_profile_file = checked(
      app.add_option(std::string(kXmlOption), fields.xml_profile_file,
                     "Fast DDS XML profiles file for the participant's QoS (its profile "
                     "replaces --interface, --udp-only and --shared-memory)"),
      rule([](const std::string& v) { return check_readable_file("XML profiles file", v); }));
  given.xml_profile = app.add_option(std::string(kProfileOption), fields.xml_profile,
                                     "participant profile in the --xml file (default: its "
                                     "default profile)");
  given.security_dir =
      checked(app.add_option(std::string(kSecurityDirOption), fields.security_dir,
                             "enable DDS Security with the credentials in DIR (as "
                             "deploy/security/make-test-pki.sh lays them out)"),
              CLI::ExistingDirectory);
  given.security_identity = checked(
      app.add_option(std::string(kSecurityIdentityOption), fields.security_identity,
                     with_default("DDS Security: the identity (sub-directory of --security-dir) "
                                  "to use",
                                  fields.security_identity)),
      rule([](const std::string& v) { return check_identity(v); }));
  return given;
}

}  // namespace dh3::contract
