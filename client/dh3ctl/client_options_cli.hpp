#pragma once
// The command-line options of a program that joins the DDS domain through
// libdh3client (dh3ctl, dh3-web, dh3-ros2): one spelling and one help text for all.

#include <CLI/CLI.hpp>
#include <optional>
#include <ostream>
#include <string>

#include "dh3/client.hpp"

namespace dh3::ctl {

/// The DDS participant's options every dh3 program shares
/// (dh3/contract/participant_flags.hpp) and --follow, bound to `options`.
void add_client_options(CLI::App& app, ClientOptions& options);

/// --log-level, one of spdlog's level names, bound to `level`.
void add_log_level_option(CLI::App& app, std::string& level);

/// Parses `argv` into `app`'s options. nullopt: go on; otherwise the code to
/// exit with: 0 after --help or --version (printed on `out`), 2 after a usage
/// error (said on `err`).
[[nodiscard]] std::optional<int> parse_command_line(CLI::App& app, int argc,
                                                    const char* const* argv, std::ostream& out,
                                                    std::ostream& err);

}  // namespace dh3::ctl
