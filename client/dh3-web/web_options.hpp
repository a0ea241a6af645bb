#pragma once
// dh3-web's command line: where it listens, who may do what, and how it joins
// the DDS domain (the same options as dh3ctl).

#include <chrono>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "dh3/base/result.hpp"
#include "dh3/client.hpp"

namespace dh3::web {

struct ListenAddress {
  std::string host = "127.0.0.1";
  int port = 8080;  ///< 0: any free port (printed at start)
};

struct WebOptions {
  ClientOptions client;
  ListenAddress listen;
  /// Further names a browser may reach dh3-web by (AllowedHosts).
  std::vector<std::string> allowed_hosts;
  std::string token_file;  ///< empty: commands are refused (viewing only)
  bool view_needs_token = false;
  double timeout_s = 10.0;  ///< each command's reply
  /// HTTP workers; each open stream holds one, so there are more of them
  /// than streams: commands, health and the page's files always find one.
  int threads = 96;
  int max_streams = 64;  ///< open streams (pages); the one past them gets 503
  std::string log_level = "info";
};

/// "ADDR:PORT", "[v6addr]:PORT" or ":PORT" (loopback).
[[nodiscard]] Result<ListenAddress, std::string> parse_listen(const std::string& text);

/// What anyone who reaches dh3-web over the network may do with these
/// options: without a token, watch every hand; with one, read it off the
/// plain-HTTP traffic. Empty on loopback, where a TLS proxy in front is the
/// only way in from elsewhere.
[[nodiscard]] std::string exposure_warning(const WebOptions& options);

/// Fills `options` from the command line. nullopt: go on; a number: exit with
/// it (after --help, --version, or a bad option reported on `err`).
/// Workers kept free of streams for everything else (--threads less --max-streams).
inline constexpr int kWorkersBesideStreams = 8;

[[nodiscard]] std::optional<int> parse_web_options(int argc, const char* const* argv,
                                                   WebOptions& options, std::ostream& out,
                                                   std::ostream& err);

}  // namespace dh3::web
