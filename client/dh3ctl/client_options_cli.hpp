#pragma once
// The command-line options of a program that joins the DDS domain through
// libdh3client (dh3ctl, dh3-web): one spelling and one help text for both.

#include <CLI/CLI.hpp>

#include "dh3/client.hpp"

namespace dh3::ctl {

/// --domain, --interface, --udp-only, --shared-memory, --xml, --profile,
/// --discovery-server, --security-dir, --security-identity and --follow, bound to `options`.
void add_client_options(CLI::App& app, ClientOptions& options);

}  // namespace dh3::ctl
