#include "dh3/base/host_port.hpp"

#include <arpa/inet.h>

namespace dh3 {

namespace {

/// The port's digits, in range for `rules`.
Result<std::uint16_t, std::string> parse_port(std::string_view digits, const HostPortRules& rules) {
  if (digits.empty()) return fail("missing port");
  if (digits.find_first_not_of("0123456789") != std::string_view::npos) {
    return fail("port '" + std::string(digits) + "' is not a number");
  }
  const std::string_view range = rules.port_zero ? "0-65535" : "1-65535";
  const auto significant = digits.find_first_not_of('0');
  const std::string_view value =
      significant == std::string_view::npos ? std::string_view("0") : digits.substr(significant);
  unsigned long port = 0;
  if (value.size() <= 5) port = std::stoul(std::string(value));
  if (value.size() > 5 || port > 65535 || (port == 0 && !rules.port_zero)) {
    return fail("port " + std::string(digits) + " is out of range " + std::string(range));
  }
  return static_cast<std::uint16_t>(port);
}

}  // namespace

Result<HostPort, std::string> parse_host_port(std::string_view text, const HostPortRules& rules) {
  HostPort address;
  std::string_view host = text;
  std::optional<std::string_view> port_text;
  if (!text.empty() && text.front() == '[') {
    const auto close = text.find(']');
    if (close == std::string_view::npos) return fail("missing ']' after the IPv6 address");
    host = text.substr(1, close - 1);
    address.bracketed = true;
    const std::string_view after = text.substr(close + 1);
    if (!after.empty()) {
      if (after.front() != ':') return fail("missing port");
      port_text = after.substr(1);
    }
  } else if (const auto colon = text.rfind(':'); colon != std::string_view::npos) {
    host = text.substr(0, colon);
    port_text = text.substr(colon + 1);
    if (host.find(':') != std::string_view::npos) {
      return fail("an IPv6 address must be in brackets, e.g. [::1]:9000");
    }
  }
  if (host.empty() && (address.bracketed || !rules.empty_host)) return fail("missing host");
  address.host = std::string(host);
  if (!port_text) {
    if (!rules.default_port) return fail("missing port");
    address.port = *rules.default_port;
    return address;
  }
  auto port = parse_port(*port_text, rules);
  if (!port) return fail(std::move(port).error());
  address.port = *port;
  return address;
}

bool is_loopback_host(std::string_view host) {
  if (host == "localhost" || host == "::1") return true;
  const std::string text(host);
  in_addr v4{};
  if (inet_pton(AF_INET, text.c_str(), &v4) == 1) return (ntohl(v4.s_addr) >> 24) == 127;
  in6_addr v6{};
  return inet_pton(AF_INET6, text.c_str(), &v6) == 1 && IN6_IS_ADDR_LOOPBACK(&v6);
}

std::string host_port_text(const std::string& host, std::uint16_t port) {
  const HostPort written{host, port, host.find(':') != std::string::npos};
  return written.written_host() + ":" + std::to_string(port);
}

}  // namespace dh3
