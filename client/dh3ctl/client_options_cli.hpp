#pragma once
// The command-line options of a program that joins the DDS domain through
// libdh3client (dh3ctl, dh3-web): one spelling and one help text for both.

#include <CLI/CLI.hpp>

#include "dh3/client.hpp"

namespace dh3::ctl {

/// The DDS participant's options every dh3 program shares
/// (dh3/contract/participant_flags.hpp) and --follow, bound to `options`.
void add_client_options(CLI::App& app, ClientOptions& options);

}  // namespace dh3::ctl
