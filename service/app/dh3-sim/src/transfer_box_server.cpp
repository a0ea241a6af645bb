#include "dh3/sim_server/transfer_box_server.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <sys/uio.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <optional>

#include "dh3/bus/receive_timestamp.hpp"
#include "dh3/protocol/codec.hpp"

namespace dh3::sim {

namespace {

constexpr std::size_t kReadChunk = 4096;

}  // namespace

std::string_view to_string(ServerError error) {
  switch (error) {
    case ServerError::bad_address:
      return "bad_address";
    case ServerError::socket_failed:
      return "socket_failed";
    case ServerError::bind_failed:
      return "bind_failed";
    case ServerError::listen_failed:
      return "listen_failed";
  }
  return "invalid ServerError";
}

TransferBoxServer::TransferBoxServer(TransferBoxServerOptions options, const Clock& clock)
    : options_(std::move(options)), host_(options_, clock) {}

Result<std::unique_ptr<TransferBoxServer>, ServerError> TransferBoxServer::open(
    TransferBoxServerOptions options, const Clock& clock) {
  std::unique_ptr<TransferBoxServer> server(new TransferBoxServer(std::move(options), clock));
  if (auto started = server->host_.start(); !started) {
    spdlog::error("dh3-sim: pipe: {}", started.error());  // the error kind has no room for why
    return fail(ServerError::socket_failed);
  }
  if (auto listening = server->listen(); !listening) return fail(listening.error());
  return server;
}

Result<void, ServerError> TransferBoxServer::listen() {
  const std::string host = options_.host == "localhost" ? "127.0.0.1" : options_.host;
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(options_.port);
  if (::inet_pton(AF_INET, host.c_str(), &address.sin_addr) != 1) {
    spdlog::error("dh3-sim: '{}' is not an IPv4 address", options_.host);
    return fail(ServerError::bad_address);
  }
  listen_fd_.reset(::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0));
  if (!listen_fd_) {
    spdlog::error("dh3-sim: socket: {}", errno_text(errno));
    return fail(ServerError::socket_failed);
  }
  const int reuse = 1;
  ::setsockopt(listen_fd_.get(), SOL_SOCKET, SO_REUSEADDR, &reuse, sizeof reuse);
  // On the listening socket, so that connections inherit it from the start: a
  // client's first frames may arrive before accept(), and unstamped they would
  // be timed by another clock than the frames after them.
  if (options_.kernel_timestamps) {
    if (const auto refused = bus::enable_receive_timestamps(listen_fd_.get())) {
      spdlog::warn("dh3-sim: no kernel receive timestamps ({}); the interval check uses "
                   "the time of reading", errno_text(*refused));
    }
  }
  if (::bind(listen_fd_.get(), reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    spdlog::error("dh3-sim: cannot listen on {}:{}: {}", host, options_.port, errno_text(errno));
    return fail(ServerError::bind_failed);
  }
  if (::listen(listen_fd_.get(), 16) != 0) {
    spdlog::error("dh3-sim: listen: {}", errno_text(errno));
    return fail(ServerError::listen_failed);
  }
  socklen_t length = sizeof address;
  ::getsockname(listen_fd_.get(), reinterpret_cast<sockaddr*>(&address), &length);
  port_ = ntohs(address.sin_port);
  return {};
}

std::string TransferBoxServer::address() const {
  const std::string host = options_.host == "localhost" ? "127.0.0.1" : options_.host;
  return host + ":" + std::to_string(port_);
}

void TransferBoxServer::run() {
  spdlog::info("dh3-sim: serving {} hand(s) on {}", host_.hand_count(), address());
  host_.run(*this);
}

void TransferBoxServer::add_poll_fds(std::vector<pollfd>& fds) {
  fds.push_back(pollfd{listen_fd_.get(), POLLIN, 0});
  for (const std::unique_ptr<Client>& client : clients_) {
    const short events = client->out.empty() ? POLLIN : POLLIN | POLLOUT;
    fds.push_back(pollfd{client->fd.get(), events, 0});
  }
}

void TransferBoxServer::on_poll(std::span<const pollfd> fds) {
  if (fds[0].revents & POLLIN) accept_clients();
  // Clients accepted or kicked above are not in `fds`; match by descriptor.
  for (const pollfd& polled : fds.subspan(1)) {
    if (polled.revents == 0) continue;
    const auto found = std::find_if(clients_.begin(), clients_.end(), [&](const auto& client) {
      return client->fd.get() == polled.fd;
    });
    if (found == clients_.end()) continue;
    Client& client = **found;
    if (polled.revents & (POLLIN | POLLHUP | POLLERR)) read_client(client);
    if (client.fd && (polled.revents & POLLOUT)) write_client(client);
  }
  std::erase_if(clients_, [](const std::unique_ptr<Client>& client) { return !client->fd; });
}

void TransferBoxServer::send(std::uint64_t destination, const protocol::Message& message) {
  for (const std::unique_ptr<Client>& client : clients_) {
    if (client->fd && (options_.shared || destination == kEveryPeer ||
                       destination == client->id)) {
      queue_for(*client, message);
    }
  }
}

void TransferBoxServer::flush() {
  for (const std::unique_ptr<Client>& client : clients_) {
    if (client->fd && !client->out.empty()) write_client(*client);
  }
}

std::optional<std::string> TransferBoxServer::execute_own(std::span<const std::string_view> words) {
  if (words.size() != 1 || words[0] != "kick") return std::nullopt;
  const std::size_t count = clients_.size();
  for (const std::unique_ptr<Client>& client : clients_) close_client(*client, "kicked");
  return "ok kick " + std::to_string(count);
}

void TransferBoxServer::accept_clients() {
  for (;;) {
    sockaddr_in peer{};
    socklen_t length = sizeof peer;
    const int fd = ::accept4(listen_fd_.get(), reinterpret_cast<sockaddr*>(&peer), &length,
                             SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd < 0) {
      if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
        spdlog::warn("dh3-sim: accept: {}", errno_text(errno));
      }
      return;
    }
    // Frames are tiny and latency matters more than packing them.
    const int no_delay = 1;
    ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &no_delay, sizeof no_delay);
    auto client = std::make_unique<Client>();
    client->fd.reset(fd);
    client->id = next_client_id_++;
    char text[INET_ADDRSTRLEN] = {};
    ::inet_ntop(AF_INET, &peer.sin_addr, text, sizeof text);
    client->peer = std::string(text) + ":" + std::to_string(ntohs(peer.sin_port));
    spdlog::info("dh3-sim: client {} connected from {}", client->id, client->peer);
    clients_.push_back(std::move(client));
  }
}

void TransferBoxServer::read_client(Client& client) {
  std::uint8_t buffer[kReadChunk];
  for (;;) {
    const bus::StampedRead read = bus::read_stamped(client.fd.get(), buffer, 0);
    if (read.got == 0) {
      close_client(client, "closed by the client");
      return;
    }
    if (read.got < 0) {
      if (read.error == EINTR) continue;
      if (read.error != EAGAIN && read.error != EWOULDBLOCK) {
        close_client(client, errno_text(read.error));
      }
      return;
    }
    decoded_.clear();
    const std::uint64_t skipped_before = client.decoder.bytes_skipped();
    client.decoder.feed(std::span(buffer, static_cast<std::size_t>(read.got)), decoded_);
    if (client.decoder.bytes_skipped() != skipped_before) {
      spdlog::debug("dh3-sim: client {}: skipped {} byte(s) that are no frame", client.id,
                    client.decoder.bytes_skipped() - skipped_before);
    }
    // One time for every frame of the read: the kernel stamps the newest
    // segment, and TCP tells no more. With stamps turned off, the time of
    // reading by the host's clock.
    const Duration read_at = options_.kernel_timestamps ? bus::arrival_time(read.stamp)
                                                        : host_.clock().now().time_since_epoch();
    for (const protocol::Message& request : decoded_) {
      if (options_.shared) share_request(client, request);
      host_.receive(request, client.id, read_at);
    }
    host_.serve_due(*this);
    if (!client.fd || static_cast<std::size_t>(read.got) < sizeof buffer) return;
  }
}

void TransferBoxServer::share_request(const Client& sender, const protocol::Message& request) {
  for (const std::unique_ptr<Client>& client : clients_) {
    if (client->fd && client->id != sender.id) queue_for(*client, request);
  }
}

void TransferBoxServer::queue_for(Client& client, const protocol::Message& message) {
  const protocol::BoxFrame frame = protocol::encode_box_frame(message);
  client.out.insert(client.out.end(), frame.begin(), frame.end());
  if (client.out.size() > options_.max_pending_bytes) {
    close_client(client, "it does not read its replies");
  }
}

void TransferBoxServer::write_client(Client& client) {
  while (!client.out.empty()) {
    const ssize_t sent =
        ::send(client.fd.get(), client.out.data(), client.out.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
    if (sent < 0) {
      if (errno == EINTR) continue;
      if (errno != EAGAIN && errno != EWOULDBLOCK) close_client(client, errno_text(errno));
      return;
    }
    client.out.erase(client.out.begin(), client.out.begin() + sent);
  }
}

void TransferBoxServer::close_client(Client& client, std::string_view why) {
  if (!client.fd) return;
  spdlog::info("dh3-sim: client {} ({}) disconnected: {}", client.id, client.peer, why);
  client.fd.reset();
  client.out.clear();
}

void TransferBoxServer::kick_all() {
  for (const std::unique_ptr<Client>& client : clients_) close_client(*client, "kicked");
  clients_.clear();
}

}  // namespace dh3::sim
