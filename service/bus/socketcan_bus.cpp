#include "bus/socketcan_bus.hpp"

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <net/if_arp.h>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <sys/ioctl.h>
#include <sys/socket.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <utility>

namespace dh3::bus {
namespace {

// DH-3 hands use CAN IDs 0-255 (spec: "Gripper ID ... range 0-255").
constexpr std::uint32_t kMaxHandId = 0xFF;
// One receive() reads at most this many datagrams so a flooded bus cannot keep
// the I/O loop from its other work; the rest waits in the socket.
constexpr int kMaxFramesPerReceive = 256;

Result<UniqueFd, std::string> new_can_socket() {
  UniqueFd fd(::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW));
  if (fd) return fd;
  const int error = errno;
  if (error == EAFNOSUPPORT || error == EPROTONOSUPPORT) {
    return dh3::fail("kernel has no CAN support: socket(PF_CAN) failed: " + errno_text(error));
  }
  return dh3::fail("socket(PF_CAN) failed: " + errno_text(error));
}

bool fill_ifreq(ifreq& request, const std::string& interface) {
  if (interface.empty() || interface.size() >= IFNAMSIZ) return false;
  std::memset(&request, 0, sizeof request);
  std::memcpy(request.ifr_name, interface.data(), interface.size());
  return true;
}

std::string bad_name(const std::string& interface) {
  return "invalid interface name '" + interface + "' (1-" + std::to_string(IFNAMSIZ - 1) +
         " characters)";
}

/// The interface's index, or why there is none.
Result<int, std::string> interface_index(int fd, const std::string& interface) {
  ifreq request{};
  if (!fill_ifreq(request, interface)) return dh3::fail(bad_name(interface));
  if (::ioctl(fd, SIOCGIFINDEX, &request) != 0) {
    if (errno == ENODEV) return dh3::fail("no network interface named '" + interface + "'");
    return dh3::fail("SIOCGIFINDEX " + interface + ": " + errno_text(errno));
  }
  return request.ifr_ifindex;
}

/// Empty if `interface` is a CAN interface, else why not.
std::string not_can_reason(int fd, const std::string& interface) {
  ifreq request{};
  if (!fill_ifreq(request, interface)) return bad_name(interface);
  if (::ioctl(fd, SIOCGIFHWADDR, &request) != 0) {
    return "SIOCGIFHWADDR " + interface + ": " + errno_text(errno);
  }
  if (request.ifr_hwaddr.sa_family != ARPHRD_CAN) {
    return "'" + interface + "' is not a CAN interface";
  }
  return {};
}

std::string link_error_text(int error) {
  if (error == ENETDOWN) return "interface is down (" + errno_text(error) + ")";
  if (error == ENODEV) return "interface disappeared (" + errno_text(error) + ")";
  return errno_text(error);
}

}  // namespace

std::string kernel_can_support_problem() {
  auto probe = new_can_socket();
  return probe ? std::string() : probe.error();
}

Result<UniqueFd, std::string> open_can_raw_socket(const std::string& interface) {
  auto created = new_can_socket();
  if (!created) return created;
  UniqueFd fd = std::move(created.value());

  const auto index = interface_index(fd.get(), interface);
  if (!index) return dh3::fail(index.error());
  if (auto reason = not_can_reason(fd.get(), interface); !reason.empty()) {
    return dh3::fail(std::move(reason));
  }
  ifreq flags{};
  fill_ifreq(flags, interface);
  if (::ioctl(fd.get(), SIOCGIFFLAGS, &flags) != 0) {
    return dh3::fail("SIOCGIFFLAGS " + interface + ": " + errno_text(errno));
  }
  if ((flags.ifr_flags & IFF_UP) == 0) {
    return dh3::fail("interface '" + interface + "' is down (ip link set " + interface + " up)");
  }

  // Standard data frames with ids 0-0xFF only: the id bits above 0xFF, the
  // extended-frame flag and the RTR flag must all be 0.
  const can_filter filter{0, CAN_EFF_FLAG | CAN_RTR_FLAG | (CAN_SFF_MASK & ~kMaxHandId)};
  if (::setsockopt(fd.get(), SOL_CAN_RAW, CAN_RAW_FILTER, &filter, sizeof filter) != 0) {
    return dh3::fail("CAN_RAW_FILTER: " + errno_text(errno));
  }
  // Controller trouble worth a log line; bus errors (chatty) are left out.
  const can_err_mask_t errors =
      CAN_ERR_TX_TIMEOUT | CAN_ERR_CRTL | CAN_ERR_BUSOFF | CAN_ERR_RESTARTED;
  if (::setsockopt(fd.get(), SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &errors, sizeof errors) != 0) {
    return dh3::fail("CAN_RAW_ERR_FILTER: " + errno_text(errno));
  }

  sockaddr_can address{};
  address.can_family = AF_CAN;
  address.can_ifindex = index.value();
  if (::bind(fd.get(), reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    return dh3::fail("bind to " + interface + ": " + errno_text(errno));
  }
  return fd;
}

Result<std::unique_ptr<SocketCanBus>, std::string> SocketCanBus::open(std::string spec,
                                                                      std::string interface,
                                                                      const Clock& clock,
                                                                      SocketCanOptions options) {
  auto probe = new_can_socket();
  if (!probe) return dh3::fail(spec + ": " + probe.error());
  ifreq request{};
  if (!fill_ifreq(request, interface)) return dh3::fail(spec + ": " + bad_name(interface));
  // An existing interface of another kind will not turn into CAN by waiting.
  if (interface_index(probe.value().get(), interface)) {
    if (auto reason = not_can_reason(probe.value().get(), interface); !reason.empty()) {
      return dh3::fail(spec + ": " + reason);
    }
  }
  CanSocketOpener opener = [interface] { return open_can_raw_socket(interface); };
  return std::make_unique<SocketCanBus>(std::move(spec), std::move(opener), clock, options);
}

SocketCanBus::SocketCanBus(std::string spec, CanSocketOpener opener, const Clock& clock,
                           SocketCanOptions options)
    : spec_(std::move(spec)),
      opener_(std::move(opener)),
      clock_(clock),
      options_(options),
      tracker_(spec_, options.reconnect) {
  try_open(clock_.now());
}

SocketCanBus::Counters SocketCanBus::counters() const {
  return Counters{tracker_.attempts(), tracker_.drops(), frames_sent_,
                  frames_received_,    frames_ignored_,  error_frames_};
}

void SocketCanBus::try_open(TimePoint now) {
  tracker_.count_attempt();
  auto opened = opener_();
  if (!opened) {
    go_down(opened.error(), now);
    return;
  }
  fd_ = std::move(opened.value());
  tracker_.mark_up();
}

void SocketCanBus::go_down(std::string_view reason, TimePoint now) {
  fd_.reset();
  tracker_.mark_down(reason, now);
}

Result<void, BusError> SocketCanBus::send(const CanFrame& frame) {
  if (frame.id > CAN_SFF_MASK || frame.length > CAN_MAX_DLEN) {
    return dh3::fail(BusError::frame_invalid);
  }
  if (!fd_) return dh3::fail(BusError::link_down);
  can_frame raw{};
  raw.can_id = frame.id;
  raw.len = frame.length;
  std::copy_n(frame.data.begin(), frame.length, raw.data);
  for (;;) {
    const ssize_t n = ::send(fd_.get(), &raw, sizeof raw, MSG_DONTWAIT | MSG_NOSIGNAL);
    if (n == static_cast<ssize_t>(sizeof raw)) {
      ++frames_sent_;
      return {};
    }
    if (n >= 0) return dh3::fail(BusError::io_error);  // a datagram is never cut
    const int error = errno;
    switch (error) {
      case EINTR:
        continue;
      case EAGAIN:
      case ENOBUFS:  // the interface's transmit queue is full
        return dh3::fail(BusError::would_block);
      case EINVAL:
      case EMSGSIZE:
      case EFAULT:
      case EOPNOTSUPP:
        return dh3::fail(BusError::io_error);
      default:  // ENETDOWN, ENODEV, EPIPE, ECONNRESET...: reopen later
        go_down("send: " + link_error_text(error), clock_.now());
        return dh3::fail(BusError::link_down);
    }
  }
}

void SocketCanBus::handle_error_frame(std::uint32_t can_id, const std::uint8_t* data) {
  ++error_frames_;
  if ((can_id & CAN_ERR_BUSOFF) != 0) spdlog::warn("{}: CAN controller is bus-off", spec_);
  if ((can_id & CAN_ERR_RESTARTED) != 0) spdlog::info("{}: CAN controller restarted", spec_);
  if ((can_id & CAN_ERR_TX_TIMEOUT) != 0) spdlog::warn("{}: CAN transmit timed out", spec_);
  if ((can_id & CAN_ERR_CRTL) != 0) {
    spdlog::debug("{}: CAN controller problem, status 0x{:02X}", spec_, data[1]);
  }
}

void SocketCanBus::read_available(std::vector<CanFrame>& out, TimePoint now) {
  for (int i = 0; i < kMaxFramesPerReceive; ++i) {
    // Room for a CAN FD frame, so an oversized datagram shows up as such
    // instead of being silently cut to the classic size.
    canfd_frame raw{};
    const ssize_t n = ::recv(fd_.get(), &raw, sizeof raw, MSG_DONTWAIT);
    if (n < 0) {
      const int error = errno;
      if (error == EINTR) continue;
      if (error == EAGAIN || error == EWOULDBLOCK) return;
      go_down("receive: " + link_error_text(error), now);
      return;
    }
    if (n == 0) {  // only a stream-like fd (a socketpair in tests) ends like this
      go_down("closed by the peer", now);
      return;
    }
    if (n != static_cast<ssize_t>(sizeof(can_frame))) {
      ++frames_ignored_;
      continue;
    }
    if ((raw.can_id & CAN_ERR_FLAG) != 0) {
      handle_error_frame(raw.can_id & CAN_ERR_MASK, raw.data);
      continue;
    }
    const std::uint32_t id = raw.can_id & CAN_SFF_MASK;
    if ((raw.can_id & (CAN_EFF_FLAG | CAN_RTR_FLAG)) != 0 || id > kMaxHandId ||
        raw.len > CAN_MAX_DLEN) {
      ++frames_ignored_;
      continue;
    }
    CanFrame frame;
    frame.id = id;
    frame.length = raw.len;
    std::copy_n(raw.data, raw.len, frame.data.begin());
    out.push_back(frame);
    ++frames_received_;
  }
}

Result<void, BusError> SocketCanBus::receive(std::vector<CanFrame>& out, Duration timeout) {
  const std::size_t frames_before = out.size();
  TimePoint now = clock_.now();
  if (!fd_ && tracker_.retry_due(now)) try_open(now);

  std::array<pollfd, 2> fds{};
  fds[0] = pollfd{wake_.fd(), POLLIN, 0};
  std::size_t count = 1;
  Duration wait = std::max(timeout, Duration::zero());
  if (fd_) {
    fds[1] = pollfd{fd_.get(), POLLIN, 0};
    count = 2;
  } else {
    wait = std::min(wait, tracker_.next_attempt_at() - now);
  }
  if (poll_fds(std::span<pollfd>(fds.data(), count), wait) < 0) {
    return dh3::fail(BusError::io_error);  // only EINVAL/ENOMEM: nothing a retry fixes
  }
  if (fds[0].revents != 0) wake_.drain();

  now = clock_.now();
  if (count == 2 && fds[1].revents != 0) {
    read_available(out, now);
  } else if (!fd_ && tracker_.retry_due(now)) {
    try_open(now);  // the backoff ran out during the wait
  }

  if (fd_ || out.size() > frames_before) return {};
  return dh3::fail(BusError::link_down);
}

}  // namespace dh3::bus
