#include "client_options_cli.hpp"

namespace dh3::ctl {

void add_client_options(CLI::App& app, ClientOptions& options) {
  app.add_option("-d,--domain", options.domain, "DDS domain id (default 0)")
      ->check(CLI::Range(0, 232));
  app.add_option("-i,--interface", options.interfaces,
                 "IPv4 address of a network interface for DDS (repeatable), or * for all; "
                 "default loopback only");
  app.add_flag("--udp-only", options.udp_only, "UDP only, no shared memory (the default)");
  app.add_flag("--shared-memory", options.shared_memory,
               "also Fast DDS's shared-memory transport on this host (needs Fast DDS 2.12.1 or "
               "later)");
  app.add_option("--xml", options.xml_profile_file,
                 "Fast DDS XML profiles file (its participant profile "
                 "replaces --interface and --udp-only)")
      ->check(CLI::ExistingFile);
  app.add_option("--profile", options.xml_profile, "participant profile name in --xml");
  app.add_option(
      "--discovery-server", options.discovery_servers,
      "a Fast DDS discovery server as HOST[:PORT] (repeatable; the n-th is server id n); "
      "default: ROS_DISCOVERY_SERVER, else multicast discovery");
  app.add_option("--security-dir", options.security_dir,
                 "DDS Security: directory of credentials as deploy/security/make-test-pki.sh "
                 "lays them out")
      ->check(CLI::ExistingDirectory);
  app.add_option("--security-identity", options.security_identity,
                 "DDS Security: the identity (folder) in --security-dir to use (default "
                 "operator; monitor: read-only)");
  app.add_option("--follow", options.follow,
                 "follow one cell, SERVICE or SERVICE/BUS: the services send this program only "
                 "its statuses, events and service info (a plant's other cells cost it nothing); "
                 "default: every service of the domain");
}

}  // namespace dh3::ctl
