#include "web_server.hpp"

#include <spdlog/spdlog.h>

#include <httplib.h>

#include "dh3/base/log_text.hpp"
#include "web_assets.hpp"

namespace dh3::web {
namespace {

/// How long a stream waits for news before it sends the services again (the
/// page's sign that the stream and the services are alive); also how soon a
/// closed browser's worker notices (the write fails).
constexpr std::chrono::seconds kHeartbeat{2};
/// Each read of a request (its line, headers, body) and each write must make
/// progress within this: a client that opens a connection and sends nothing,
/// or a byte now and then, frees its worker instead of holding it.
constexpr std::chrono::seconds kReadWriteTimeout{5};
/// An idle keep-alive connection holds a worker this long at most, and serves
/// this many requests before it is closed.
constexpr time_t kKeepAliveSeconds = 2;
constexpr std::size_t kKeepAliveRequests = 100;
/// Bodies are a few numbers; anything larger is a mistake or an attack.
constexpr std::size_t kMaxBody = 64 * 1024;
/// A request for a Host name dh3-web does not answer to.
constexpr int kMisdirected = 421;

void add_common_headers(httplib::Response& res) {
  res.set_header("X-Content-Type-Options", "nosniff");
  res.set_header("Cache-Control", "no-store");
  // The page drives machines: no other site may frame it (clickjacking),
  // and it loads nothing but its own files.
  res.set_header("X-Frame-Options", "DENY");
  res.set_header("Content-Security-Policy",
                 "default-src 'self'; frame-ancestors 'none'; base-uri 'none'; form-action 'none'");
}

void send(httplib::Response& res, const ApiResponse& response) {
  res.status = response.status;
  if (!response.allow.empty()) res.set_header("Allow", response.allow);
  if (response.ask_for_token) res.set_header("WWW-Authenticate", "Bearer realm=\"dh3-web\"");
  res.set_content(response.body + "\n", "application/json");
}

ApiRequest to_api_request(const httplib::Request& req) {
  return ApiRequest{req.method, req.path, req.get_header_value("Authorization"), req.body};
}

}  // namespace

WebServer::WebServer(HandApi& api, EventStream& stream, int threads, AllowedHosts hosts)
    : api_(api),
      stream_(stream),
      hosts_(std::move(hosts)),
      server_(std::make_unique<httplib::Server>()) {
  const auto pool_size = static_cast<std::size_t>(threads);
  server_->new_task_queue = [pool_size] { return new httplib::ThreadPool(pool_size); };
  server_->set_payload_max_length(kMaxBody);
  server_->set_keep_alive_timeout(kKeepAliveSeconds);
  server_->set_keep_alive_max_count(kKeepAliveRequests);
  server_->set_read_timeout(kReadWriteTimeout);
  server_->set_write_timeout(kReadWriteTimeout);
  server_->set_logger([](const httplib::Request& req, const httplib::Response& res) {
    // The path without its query and no header but a refused Host: the token
    // stays out. What the sender wrote is escaped: it cannot start a line.
    spdlog::info("{} {} {} {}{}", req.remote_addr, escaped_for_log(req.method),
                 escaped_for_log(req.path), res.status,
                 res.status == kMisdirected
                     ? " Host: " + escaped_for_log(req.get_header_value("Host"))
                     : std::string());
  });
  server_->set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
    if (hosts_.allows(req.get_header_value("Host"))) {
      return httplib::Server::HandlerResponse::Unhandled;
    }
    send(res, error_response({kMisdirected, "MISDIRECTED_REQUEST",
                              "dh3-web does not answer to this Host name (a page of another "
                              "site?); give dh3-web --allow-host NAME to serve under it"}));
    return httplib::Server::HandlerResponse::Handled;
  });
  // httplib's own refusals (a POST without Content-Length, a body over the
  // limit, a request it cannot parse) come without a body: say it in JSON too.
  const httplib::Server::HandlerWithResponse on_error = [](const httplib::Request& req,
                                                          httplib::Response& res) {
    if (!res.body.empty()) return httplib::Server::HandlerResponse::Unhandled;
    ApiError error{res.status, "BAD_REQUEST", "the request could not be read"};
    if (res.status == 404) error = {404, "NOT_FOUND", "nothing at " + req.method + " " + req.path};
    if (res.status == 413) {
      error = {413, "PAYLOAD_TOO_LARGE",
               "the body is larger than " + std::to_string(kMaxBody) + " bytes"};
    }
    if (res.status == 400 && req.body.empty()) {
      error.message += " (a POST needs a Content-Length: 0 for no body, or a JSON body such as {})";
    }
    send(res, error_response(error));
    return httplib::Server::HandlerResponse::Handled;
  };
  server_->set_error_handler(on_error);
  server_->set_post_routing_handler(
      [](const httplib::Request&, httplib::Response& res) { add_common_headers(res); });
  add_routes();
}

WebServer::~WebServer() = default;

void WebServer::add_routes() {
  auto& s = *server_;
  s.Get("/api/stream", [this](const httplib::Request& req, httplib::Response& res) {
    if (auto refused = api_.authorize_view(req.get_header_value("Authorization"))) {
      send(res, *refused);
      return;
    }
    auto reader = stream_.open();
    if (!reader) {
      // Viewers may not take the workers that commands and Stop need.
      send(res, error_response({503, "TOO_MANY_STREAMS",
                                "dh3-web serves " + std::to_string(stream_.max_readers()) +
                                    " open pages at most (--max-streams); close one, or "
                                    "start dh3-web with more"}));
      res.set_header("Retry-After", "5");
      return;
    }
    res.set_header("X-Accel-Buffering", "no");  // a proxy in front must not buffer the stream
    res.set_chunked_content_provider("text/event-stream",
                                     [this, reader, last_beat = std::chrono::steady_clock::now()](
                                         std::size_t /*offset*/, httplib::DataSink& sink) mutable {
                                       auto text = reader->next(kHeartbeat);
                                       if (!text) {
                                         sink.done();
                                         return true;
                                       }
                                       // Also between statuses: a service lost among others that go
                                       // on publishing is seen by its info, which changes no
                                       // status.
                                       const auto now = std::chrono::steady_clock::now();
                                       if (text->empty() || now - last_beat >= kHeartbeat) {
                                         *text += stream_.heartbeat();
                                         last_beat = now;
                                       }
                                       return sink.write(text->data(), text->size());
                                     });
  });
  const auto api = [this](const httplib::Request& req, httplib::Response& res) {
    send(res, api_.handle(to_api_request(req)));
  };
  s.Get("/api/.*", api);
  s.Post("/api/.*", api);
  s.Put("/api/.*", api);
  s.Patch("/api/.*", api);
  s.Delete("/api/.*", api);
  s.Options("/api/.*", api);
  s.Get("/.*", [](const httplib::Request& req, httplib::Response& res) {
    const WebAsset* asset = find_asset(req.path == "/index.html" ? "/" : req.path);
    if (asset == nullptr) {
      res.status = 404;
      res.set_content("not found: " + req.path + "\n", "text/plain; charset=utf-8");
      return;
    }
    res.set_content(std::string(asset->body), std::string(asset->content_type));
  });
}

Result<int, std::string> WebServer::bind(const ListenAddress& listen) {
  const int port = listen.port == 0
                       ? server_->bind_to_any_port(listen.host)
                       : (server_->bind_to_port(listen.host, listen.port) ? listen.port : -1);
  if (port <= 0) {
    return fail("cannot listen on " + listen.host + ":" + std::to_string(listen.port) +
                " (address in use, or not an address of this machine?)");
  }
  return port;
}

void WebServer::run() {
  server_->listen_after_bind();
}

void WebServer::stop() {
  server_->stop();
}

}  // namespace dh3::web
