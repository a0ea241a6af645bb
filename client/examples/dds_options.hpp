#pragma once
// The command-line options with which both examples join the DDS domain, each
// filling its field of dh3::ClientOptions. The examples use only the installed
// library, so they spell these themselves; dh3's own programs take theirs from
// the contract (dh3/contract/participant_flags.hpp).

#include <CLI/CLI.hpp>

#include "dh3/client.hpp"

inline void add_dds_options(CLI::App& app, dh3::ClientOptions& options) {
  app.add_option("-d,--domain", options.domain, "DDS domain id (default 0)");
  app.add_option("-i,--interface", options.interfaces,
                 "IPv4 address of a network interface for DDS (repeatable); default loopback");
  app.add_flag("--udp-only", options.udp_only, "no shared-memory transport");
  app.add_option("--discovery-server", options.discovery_servers,
                 "a Fast DDS discovery server, HOST[:PORT] (repeatable; the n-th is server id n)");
  app.add_option("--xml", options.xml_profile_file,
                 "Fast DDS XML profiles file (replaces --interface and --udp-only)")
      ->check(CLI::ExistingFile);
  app.add_option("--profile", options.xml_profile, "participant profile name in --xml");
  app.add_option("--security-dir", options.security_dir,
                 "DDS Security credentials, as deploy/security/make-test-pki.sh lays them out")
      ->check(CLI::ExistingDirectory);
  app.add_option("--security-identity", options.security_identity,
                 "identity in --security-dir (default operator)");
}
