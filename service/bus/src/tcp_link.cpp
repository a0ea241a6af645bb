#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>

#include <algorithm>
#include <cerrno>
#include <memory>
#include <vector>

#include "dh3/base/host_port.hpp"
#include "dh3/bus/stream_link.hpp"

namespace dh3::bus {
namespace {

struct AddrInfoDeleter {
  void operator()(addrinfo* info) const { ::freeaddrinfo(info); }
};

int seconds_at_least_one(Duration d) {
  const auto s = std::chrono::duration_cast<std::chrono::seconds>(d).count();
  return static_cast<int>(std::clamp<decltype(s)>(s, 1, 3600));
}

// Best effort: a socket without these options still works, it just notices a
// silent peer later.
void set_dead_peer_timeout(int fd, Duration timeout) {
  if (timeout <= Duration::zero()) return;
  const int on = 1;
  const int idle = seconds_at_least_one(timeout / 2);
  const int interval = seconds_at_least_one(timeout / 6);
  const int count = 3;
  const auto user_timeout_ms =
      static_cast<unsigned>(std::chrono::duration_cast<std::chrono::milliseconds>(timeout).count());
  ::setsockopt(fd, SOL_SOCKET, SO_KEEPALIVE, &on, sizeof on);
  ::setsockopt(fd, IPPROTO_TCP, TCP_KEEPIDLE, &idle, sizeof idle);
  ::setsockopt(fd, IPPROTO_TCP, TCP_KEEPINTVL, &interval, sizeof interval);
  ::setsockopt(fd, IPPROTO_TCP, TCP_KEEPCNT, &count, sizeof count);
  ::setsockopt(fd, IPPROTO_TCP, TCP_USER_TIMEOUT, &user_timeout_ms, sizeof user_timeout_ms);
}

}  // namespace

TcpLink::TcpLink(std::string host, std::uint16_t port, TcpLinkOptions options)
    : host_(std::move(host)), port_(port), options_(options) {}

std::string TcpLink::describe() const {
  return "tcp " + host_port_text(host_, port_);
}

Result<OpenStarted, std::string> TcpLink::start_open() {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_NUMERICSERV;
  addrinfo* raw = nullptr;
  // Numeric addresses resolve at once; names go through the system resolver,
  // whose own timeouts bound this call.
  const int resolved = ::getaddrinfo(host_.c_str(), std::to_string(port_).c_str(), &hints, &raw);
  if (resolved != 0) {
    return dh3::fail("cannot resolve '" + host_ + "': " + ::gai_strerror(resolved));
  }
  const std::unique_ptr<addrinfo, AddrInfoDeleter> addresses(raw);
  std::vector<const addrinfo*> candidates;
  for (const addrinfo* a = addresses.get(); a != nullptr; a = a->ai_next) candidates.push_back(a);
  if (candidates.empty()) return dh3::fail("'" + host_ + "' has no address");
  const addrinfo& target = *candidates[next_address_++ % candidates.size()];

  UniqueFd fd(::socket(target.ai_family, target.ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC,
                       target.ai_protocol));
  if (!fd) return dh3::fail("socket(): " + errno_text(errno));
  const int on = 1;
  // Frames are 14 bytes and latency matters more than packing them.
  ::setsockopt(fd.get(), IPPROTO_TCP, TCP_NODELAY, &on, sizeof on);
  set_dead_peer_timeout(fd.get(), options_.dead_peer_timeout);

  if (::connect(fd.get(), target.ai_addr, target.ai_addrlen) == 0) {
    return OpenStarted{std::move(fd), false};
  }
  if (errno == EINPROGRESS) return OpenStarted{std::move(fd), true};
  return dh3::fail("connect to " + describe() + ": " + errno_text(errno));
}

Result<void, std::string> TcpLink::finish_open(int fd) {
  int error = 0;
  socklen_t length = sizeof error;
  if (::getsockopt(fd, SOL_SOCKET, SO_ERROR, &error, &length) != 0) error = errno;
  if (error != 0) return dh3::fail("connect to " + describe() + ": " + errno_text(error));
  return {};
}

ssize_t TcpLink::write_some(int fd, std::span<const std::uint8_t> bytes) {
  return ::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
}

ssize_t TcpLink::read_some(int fd, std::span<std::uint8_t> bytes) {
  return ::recv(fd, bytes.data(), bytes.size(), MSG_DONTWAIT);
}

}  // namespace dh3::bus
