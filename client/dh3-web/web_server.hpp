#pragma once
// The HTTP side of dh3-web on cpp-httplib: the page's files, the API (all of
// it HandApi's but the push stream), an access log without secrets.

#include <memory>
#include <string>

#include "allowed_hosts.hpp"
#include "dh3/base/result.hpp"
#include "event_stream.hpp"
#include "hand_api.hpp"
#include "web_options.hpp"

namespace httplib {
class Server;
}

namespace dh3::web {

class WebServer {
 public:
  /// `threads`: the worker pool; each open stream holds one worker.
  /// Requests for a host `hosts` does not allow are answered 421.
  WebServer(HandApi& api, EventStream& stream, int threads, AllowedHosts hosts);
  ~WebServer();
  WebServer(const WebServer&) = delete;
  WebServer& operator=(const WebServer&) = delete;

  /// Binds the port; the port bound (the one asked for, or a free one for 0).
  Result<int, std::string> bind(const ListenAddress& listen);
  /// Serves until stop(); call after bind().
  void run();
  /// From any thread. Close the EventStream first: open streams hold workers.
  void stop();

 private:
  void add_routes();

  HandApi& api_;
  EventStream& stream_;
  AllowedHosts hosts_;
  std::unique_ptr<httplib::Server> server_;
};

}  // namespace dh3::web
