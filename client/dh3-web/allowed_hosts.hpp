#pragma once
// The names under which dh3-web answers, checked against each request's Host
// header. A page of another site can make its own name resolve to this
// machine (DNS rebinding) and then read the hands as if it were dh3-web's own
// page; its requests still carry its name, which is not one of these.

#include <string>
#include <string_view>
#include <vector>

namespace dh3::web {

class AllowedHosts {
 public:
  /// For dh3-web listening on `listen_host`: that address; on loopback also
  /// localhost, 127.0.0.1 and ::1; on every interface (0.0.0.0, ::) any
  /// address literal, localhost and this machine's name; and `names`
  /// (--allow-host: a proxy's or a DNS name), all without regard to case.
  AllowedHosts(const std::string& listen_host, const std::vector<std::string>& names);

  /// True when a request whose Host header is `host` may be served. The port
  /// is not compared (a proxy in front may rewrite it); a request without a
  /// Host header (HTTP/1.0) is served: no browser sends one.
  [[nodiscard]] bool allows(std::string_view host) const;

 private:
  std::vector<std::string> names_;
  bool any_address_ = false;
};

}  // namespace dh3::web
