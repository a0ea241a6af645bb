// check_config: reads dh3-service configuration files exactly as dh3-service
// does (load, then the command line's checks with no options given) and says
// for each whether the service would start with it.
//
//   check_config FILE...     prints "ok FILE" or "error MESSAGE"; exit 1 on any error

#include <cstdio>
#include <utility>

#include "dh3/app/config.hpp"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: check_config FILE...\n");
    return 2;
  }
  int status = 0;
  for (int i = 1; i < argc; ++i) {
    auto loaded = dh3::app::load_config(argv[i]);
    if (!loaded) {
      std::printf("error %s\n", loaded.error().message.c_str());
      status = 1;
      continue;
    }
    auto config = dh3::app::apply_command_line(std::move(*loaded), dh3::app::CommandLine{});
    if (!config) {
      std::printf("error %s: %s\n", argv[i], config.error().message.c_str());
      status = 1;
      continue;
    }
    std::printf("ok %s: service '%s', domain %d, %zu bus(es)\n", argv[i], config->name.c_str(),
                config->participant.domain, config->buses.size());
  }
  return status;
}
