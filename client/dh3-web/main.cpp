// dh3-web: the hands of a DDS domain in a browser, and an HTTP API for
// controllers that speak no DDS. A client of the domain like dh3ctl.

#include <spdlog/spdlog.h>

#include <csignal>
#include <iostream>
#include <thread>

#include "cell_alarms.hpp"
#include "dh3/base/host_name.hpp"
#include "dh3/base/stop_signals.hpp"
#include "dh3/client.hpp"
#include "event_stream.hpp"
#include "hand_api.hpp"
#include "web_assets.hpp"
#include "web_options.hpp"
#include "web_server.hpp"

namespace {

std::string url(const dh3::web::ListenAddress& listen, int port) {
  const bool v6 = listen.host.find(':') != std::string::npos;
  return "http://" + (v6 ? "[" + listen.host + "]" : listen.host) + ":" + std::to_string(port) +
         "/";
}

}  // namespace

int main(int argc, char** argv) {
  const sigset_t signals = dh3::block_stop_signals();

  dh3::web::WebOptions options;
  if (auto exit_code = dh3::web::parse_web_options(argc, argv, options, std::cout, std::cerr)) {
    return *exit_code;
  }
  spdlog::set_level(spdlog::level::from_str(options.log_level));
  if (const auto warning = dh3::web::exposure_warning(options); !warning.empty()) {
    spdlog::warn("{}", warning);
  }

  dh3::web::AccessPolicy access;
  access.view_needs_token = options.view_needs_token;
  if (!options.token_file.empty()) {
    auto token = dh3::web::BearerToken::from_file(options.token_file);
    if (!token) {
      std::cerr << "dh3-web: " << token.error() << "\n";
      return 2;
    }
    access.token = std::move(token).value();
  }

  dh3::Client client(options.client);
  if (!client.connected()) {
    std::cerr << "dh3-web: " << client.error() << "\n";
    return 1;
  }
  dh3::web::EventStreamOptions stream_options;
  stream_options.max_readers = static_cast<std::size_t>(options.max_streams);
  dh3::web::EventStream stream(client, stream_options);
  // After the stream, so it is destroyed first: nothing sends to a stream that is gone.
  dh3::web::CellAlarms alarms(client);
  alarms.set_listener([&stream](std::uint64_t version, const std::string& json) {
    stream.publish_alarms(version, json);
  });
  stream.publish_alarms(0, alarms.alarms_json());
  const auto* openapi = dh3::web::find_asset("/api/openapi.json");
  dh3::web::HandApi api(client, access, client.default_timeout(),
                        openapi == nullptr ? "{}" : std::string(openapi->body),
                        dh3::program_at_host(options.client.participant_name), &alarms);
  dh3::web::WebServer server(api, stream, options.threads,
                             dh3::web::AllowedHosts(options.listen.host, options.allowed_hosts));
  auto port = server.bind(options.listen);
  if (!port) {
    std::cerr << "dh3-web: " << port.error() << "\n";
    return 1;
  }
  // One line on stdout for people and for scripts that start it on port 0.
  std::cout << "dh3-web: serving " << url(options.listen, *port) << " (domain "
            << options.client.domain << "; commands "
            << (access.token ? "need the bearer token" : "off: no --token-file") << "; viewing "
            << (access.view_needs_token ? "needs the token" : "open") << ")" << std::endl;

  std::thread serving([&server] { server.run(); });
  int signal_number = 0;
  sigwait(&signals, &signal_number);
  spdlog::info("dh3-web: signal {}, stopping", signal_number);
  stream.close();  // open streams end, so their workers are free to stop
  server.stop();
  serving.join();
  return 0;
}
