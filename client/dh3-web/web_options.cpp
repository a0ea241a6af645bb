#include "web_options.hpp"

#include <unistd.h>

#include <CLI/CLI.hpp>

#include "client_options_cli.hpp"
#include "dh3/base/host_port.hpp"
#include "dh3/base/version.hpp"

namespace dh3::web {

Result<ListenAddress, std::string> parse_listen(const std::string& text) {
  HostPortRules listening;
  listening.port_zero = true;
  listening.empty_host = true;
  auto address = parse_host_port(text, listening);
  if (!address) {
    return fail("--listen " + text + ": " + address.error() +
                " (expected ADDR:PORT, e.g. 127.0.0.1:8080)");
  }
  ListenAddress listen;
  if (!address->host.empty()) listen.host = std::move(address->host);
  listen.port = address->port;
  return listen;
}

std::string exposure_warning(const WebOptions& options) {
  if (is_loopback_host(options.listen.host)) return {};
  if (options.token_file.empty()) {
    return "dh3-web listens on " + options.listen.host +
           " without --token-file: anyone on that network can watch every hand (status, "
           "position, events) and see who holds its lease; commands are off. Listen on "
           "127.0.0.1 behind a TLS proxy, or give --token-file (docs/security.md)";
  }
  return "dh3-web listens on " + options.listen.host +
         " over plain HTTP: the bearer token crosses that network in clear text, and "
         "anyone who reads the traffic can take it and drive every hand" +
         (options.view_needs_token ? "" : "; anyone there can watch every hand without it") +
         ". Listen on 127.0.0.1 behind a TLS proxy (docs/security.md)";
}

std::optional<int> parse_web_options(int argc, const char* const* argv, WebOptions& options,
                                     std::ostream& out, std::ostream& err) {
  CLI::App app{
      "dh3-web: a web console and an HTTP API for DH-3 hands on a DDS domain.\n"
      "Serves the page at / and the JSON API at /api/ (described at /api/openapi.json)."};
  app.name("dh3-web");
  app.set_version_flag("--version", kVersion);
  std::string listen = "127.0.0.1:8080";
  app.add_option("--listen", listen,
                 "ADDR:PORT to serve on (default 127.0.0.1:8080: this machine only; port 0: any "
                 "free port)");
  app.add_option("--allow-host", options.allowed_hosts,
                 "a name browsers reach dh3-web by besides its --listen address and, on "
                 "loopback, localhost (repeatable): a proxy's, a DNS name. Requests for "
                 "other names are refused (421)");
  app.add_option("--token-file", options.token_file,
                 "the bearer tokens: a first line of one token (an operator's), or lines "
                 "'ROLE TOKEN', ROLE view, operator or admin (admin: also set-can-id and "
                 "set-baud); without it dh3-web only shows the hands")
      ->check(CLI::ExistingFile);
  app.add_flag("--view-needs-token", options.view_needs_token,
               "statuses, events and the stream need the token too (default: open to whoever "
               "reaches the address)");
  app.add_option("-t,--timeout", options.timeout_s,
                 "seconds to wait for each command's reply (default 10)")
      ->check(CLI::PositiveNumber);
  app.add_option("--threads", options.threads,
                 "HTTP worker threads (default 96); each open page's stream holds one, the "
                 "others serve commands, health and the page")
      ->check(CLI::Range(2, 4096));
  app.add_option("--max-streams", options.max_streams,
                 "open pages (event streams) served at once (default 64); the one past them "
                 "is answered 503. At least 8 fewer than --threads")
      ->check(CLI::Range(1, 4000));
  ctl::add_log_level_option(app, options.log_level);
  ctl::add_client_options(app, options.client);
  if (auto code = ctl::parse_command_line(app, argc, argv, out, err)) return code;
  auto parsed = parse_listen(listen);
  if (!parsed) {
    err << "dh3-web: " << parsed.error() << "\n";
    return 2;
  }
  options.listen = *parsed;
  if (options.view_needs_token && options.token_file.empty()) {
    err << "dh3-web: --view-needs-token needs --token-file\n";
    return 2;
  }
  if (options.threads - options.max_streams < kWorkersBesideStreams) {
    err << "dh3-web: --threads " << options.threads << " leaves too few workers beside "
        << "--max-streams " << options.max_streams << " (give at least "
        << options.max_streams + kWorkersBesideStreams
        << " threads): open pages would keep commands waiting\n";
    return 2;
  }
  // The process id tells two consoles on one host apart where a lease's
  // holder is shown, and lets a page know the leases of its own console.
  options.client.participant_name = "dh3-web-" + std::to_string(::getpid());
  options.client.default_timeout =
      std::chrono::milliseconds(static_cast<std::int64_t>(options.timeout_s * 1000.0));
  return std::nullopt;
}

}  // namespace dh3::web
