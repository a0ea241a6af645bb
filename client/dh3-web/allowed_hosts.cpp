#include "allowed_hosts.hpp"

#include <arpa/inet.h>

#include <algorithm>
#include <cctype>

#include "dh3/base/host_name.hpp"
#include "dh3/base/host_port.hpp"

namespace dh3::web {
namespace {

std::string lowercase(std::string_view text) {
  std::string lower(text);
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return lower;
}

/// The name of a Host header without its port, brackets and final dot:
/// "[::1]:8080" -> "::1", "Cell-PC.:8080" -> "cell-pc".
std::string host_name_of(std::string_view header) {
  std::string_view name = header;
  if (name.starts_with('[')) {
    const auto close = name.find(']');
    name = name.substr(1, close == std::string_view::npos ? std::string_view::npos : close - 1);
  } else if (const auto colon = name.find(':');
             colon != std::string_view::npos &&
             name.find(':', colon + 1) == std::string_view::npos) {
    name = name.substr(0, colon);
  }
  if (name.ends_with('.')) name.remove_suffix(1);
  return lowercase(name);
}

bool is_address_literal(const std::string& name) {
  unsigned char address[sizeof(in6_addr)];
  return inet_pton(AF_INET, name.c_str(), address) == 1 ||
         inet_pton(AF_INET6, name.c_str(), address) == 1;
}

}  // namespace

AllowedHosts::AllowedHosts(const std::string& listen_host, const std::vector<std::string>& names) {
  any_address_ = listen_host == "0.0.0.0" || listen_host == "::";
  if (!any_address_) names_.push_back(lowercase(listen_host));
  if (any_address_ || is_loopback_host(listen_host)) {
    names_.insert(names_.end(), {"localhost", "127.0.0.1", "::1"});
  }
  if (any_address_ && !host_name().empty()) names_.push_back(lowercase(host_name()));
  for (const auto& name : names) names_.push_back(host_name_of(name));
}

bool AllowedHosts::allows(std::string_view host) const {
  if (host.empty()) return true;
  const std::string name = host_name_of(host);
  if (any_address_ && is_address_literal(name)) return true;
  return std::find(names_.begin(), names_.end(), name) != names_.end();
}

}  // namespace dh3::web
