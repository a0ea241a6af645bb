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

}  // namespace dh3::ctl
