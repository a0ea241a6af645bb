#include "client_options_cli.hpp"

#include "dh3/contract/participant_flags.hpp"

namespace dh3::ctl {

void add_client_options(CLI::App& app, ClientOptions& options) {
  contract::add_participant_options(app, contract::fields_of(options),
                                    contract::FlagChecks::on_parse);
  app.add_option("--follow", options.follow,
                 "follow one cell, SERVICE or SERVICE/BUS: the services send this program only "
                 "its statuses, events and service info (a plant's other cells cost it nothing); "
                 "default: every service of the domain");
}

void add_log_level_option(CLI::App& app, std::string& level) {
  app.add_option("--log-level", level, "trace, debug, info, warn, error (default info)")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}));
}

std::optional<int> parse_command_line(CLI::App& app, int argc, const char* const* argv,
                                      std::ostream& out, std::ostream& err) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    return app.exit(error, out, err) == 0 ? 0 : 2;
  }
  return std::nullopt;
}

}  // namespace dh3::ctl
