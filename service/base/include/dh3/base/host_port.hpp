#pragma once
// HOST:PORT, the one grammar of a network address in dh3: the transfer box a
// bus connects to, the metrics and dh3-web listening addresses, dh3-sim's
// listening address and the discovery servers. An IPv6 address is written in
// brackets ("[::1]:9000"), so the last ':' always separates the port.
//
// The grammar only: whether a host must be an address literal, or may be a
// name to resolve, is the caller's rule.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "dh3/base/result.hpp"

namespace dh3 {

struct HostPort {
  std::string host;  ///< without the brackets of an IPv6 address; empty only if allowed
  std::uint16_t port = 0;
  bool bracketed = false;  ///< the host was written in brackets (IPv6)

  /// The host as written: an IPv6 address in brackets.
  [[nodiscard]] std::string written_host() const { return bracketed ? "[" + host + "]" : host; }
};

/// HOST:PORT as it is written back: a host with a ':' (IPv6) in brackets.
[[nodiscard]] std::string host_port_text(const std::string& host, std::uint16_t port);

/// What an address may leave out; the defaults ask for everything.
struct HostPortRules {
  /// Port 0 (any free port) is allowed: a listening address.
  bool port_zero = false;
  /// The port may be left out ("HOST"): this one is used then.
  std::optional<std::uint16_t> default_port = std::nullopt;
  /// The host may be left out (":PORT"): the caller's default host.
  bool empty_host = false;
};

/// HOST:PORT or [IPV6]:PORT; the error says what is wrong ("missing port",
/// "missing host", "port 'x' is not a number", "port 70000 is out of range
/// 1-65535", "an IPv6 address must be in brackets, e.g. [::1]:9000",
/// "missing ']' after the IPv6 address").
[[nodiscard]] Result<HostPort, std::string> parse_host_port(std::string_view text,
                                                            const HostPortRules& rules = {});

/// True for an address that only this machine reaches: 127.0.0.0/8, ::1, and
/// the name "localhost". False for anything else, the wildcards 0.0.0.0 and
/// :: (every interface) included.
[[nodiscard]] bool is_loopback_host(std::string_view host);

}  // namespace dh3
