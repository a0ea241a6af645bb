#include "dh3/bus/socketcan_bus.hpp"

#include <linux/can.h>
#include <linux/can/error.h>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <sys/uio.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <optional>
#include <utility>

#include "dh3/bus/receive_timestamp.hpp"

namespace dh3::bus {
namespace {

// One receive() reads at most this many datagrams so a flooded bus cannot keep
// the I/O loop from its other work; the rest waits in the socket.
constexpr int kMaxFramesPerReceive = 256;
// A kind of error frame is logged at most once in this long (with its count).
constexpr Duration kErrorLogInterval = std::chrono::seconds(10);

std::size_t index_of(ErrorFrameKind kind) { return static_cast<std::size_t>(kind); }

std::string link_error_text(int error) {
  if (error == ENETDOWN) return "interface is down (" + errno_text(error) + ")";
  if (error == ENODEV) return "interface disappeared (" + errno_text(error) + ")";
  return errno_text(error);
}

}  // namespace

std::bitset<kErrorFrameKinds> classify_error_frame(std::uint32_t can_id, const std::uint8_t* data) {
  std::bitset<kErrorFrameKinds> kinds;
  auto mark = [&kinds](ErrorFrameKind kind) { kinds.set(index_of(kind)); };
  if ((can_id & CAN_ERR_BUSOFF) != 0) mark(ErrorFrameKind::bus_off);
  if ((can_id & CAN_ERR_RESTARTED) != 0) mark(ErrorFrameKind::restarted);
  if ((can_id & CAN_ERR_TX_TIMEOUT) != 0) mark(ErrorFrameKind::tx_timeout);
  if ((can_id & CAN_ERR_LOSTARB) != 0) mark(ErrorFrameKind::lost_arbitration);
  if ((can_id & CAN_ERR_PROT) != 0) mark(ErrorFrameKind::protocol_violation);
  if ((can_id & CAN_ERR_TRX) != 0) mark(ErrorFrameKind::transceiver);
  if ((can_id & CAN_ERR_ACK) != 0) mark(ErrorFrameKind::no_ack);
  if ((can_id & CAN_ERR_BUSERROR) != 0) mark(ErrorFrameKind::bus_error);
  if ((can_id & CAN_ERR_CRTL) != 0) {
    const std::uint8_t status = data[1];
    if ((status & (CAN_ERR_CRTL_RX_OVERFLOW | CAN_ERR_CRTL_TX_OVERFLOW)) != 0) {
      mark(ErrorFrameKind::controller_overflow);
    }
    if ((status & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) != 0) {
      mark(ErrorFrameKind::error_warning);
    }
    if ((status & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) != 0) {
      mark(ErrorFrameKind::error_passive);
    }
    if ((status & CAN_ERR_CRTL_ACTIVE) != 0) mark(ErrorFrameKind::error_active);
  }
  return kinds;
}

Result<std::unique_ptr<SocketCanBus>, std::string> SocketCanBus::open(std::string spec,
                                                                      std::string interface,
                                                                      const Clock& clock,
                                                                      SocketCanOptions options) {
  if (auto problem = lasting_can_interface_problem(interface); !problem.empty()) {
    return dh3::fail(spec + ": " + problem);
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
  return Counters{tracker_.attempts(), tracker_.drops(),       frames_sent_,
                  frames_received_,    frames_ignored_.load(), error_frames_};
}

BusDiagnostics SocketCanBus::diagnostics() const {
  BusDiagnostics out;
  out.sees_controller = true;
  out.bus_off = bus_off_.load(std::memory_order_relaxed);
  for (std::size_t i = 0; i < kErrorFrameKinds; ++i) {
    out.error_frames[i] = error_kinds_[i].load(std::memory_order_relaxed);
  }
  out.rx_overflow_drops = rx_overflow_drops_.load(std::memory_order_relaxed);
  out.frames_ignored = frames_ignored_.load(std::memory_order_relaxed);
  return out;
}

void SocketCanBus::try_open(TimePoint now) {
  tracker_.count_attempt();
  auto opened = opener_();
  if (!opened) {
    go_down(opened.error(), now);
    return;
  }
  fd_ = std::move(opened.value());
  if (options_.receive_timestamps) {
    if (const auto refused = enable_receive_timestamps(fd_.get())) {
      spdlog::warn("{}: no kernel receive timestamps ({}); frames are recorded at the time of "
                   "reading",
                   spec_, errno_text(*refused));
    }
  }
  kernel_drops_seen_ = 0;
  bus_off_.store(false);  // a fresh socket on an interface that is up
  tracker_.mark_up();
}

void SocketCanBus::go_down(std::string_view reason, TimePoint now) {
  fd_.reset();
  bus_off_.store(false);
  tracker_.mark_down(reason, now);
}

void SocketCanBus::end_bus_off(std::string_view why) {
  if (!bus_off_.exchange(false)) return;
  spdlog::info("{}: CAN controller back on the bus ({})", spec_, why);
  tracker_.mark_up();
}

Result<void, BusError> SocketCanBus::send(const CanFrame& frame) {
  auto sent = send_burst(std::span(&frame, 1));
  if (!sent) return dh3::fail(sent.error());
  return {};
}

Result<std::size_t, BusError> SocketCanBus::send_burst(std::span<const CanFrame> frames) {
  // A group has at most GROUP_MAX_HANDS (64) members; larger bursts go in rounds.
  constexpr std::size_t kMaxBurst = 64;
  std::size_t count = std::min(frames.size(), kMaxBurst);
  const auto invalid = std::find_if(frames.begin(), frames.begin() + count, [](const CanFrame& f) {
    return f.id > CAN_SFF_MASK || f.length > CAN_MAX_DLEN;
  });
  count = static_cast<std::size_t>(invalid - frames.begin());
  if (count == 0) {
    if (frames.empty()) return std::size_t{0};
    return dh3::fail(BusError::frame_invalid);
  }
  if (!can_carry_frames()) return dh3::fail(BusError::link_down);
  // Not value-initialised: every send() comes here, and only `count` entries
  // (one, but for a group) are used; each is cleared as it is filled.
  std::array<can_frame, kMaxBurst> raw;
  std::array<iovec, kMaxBurst> io;
  std::array<mmsghdr, kMaxBurst> messages;
  for (std::size_t i = 0; i < count; ++i) {
    raw[i] = can_frame{};
    messages[i] = mmsghdr{};
    raw[i].can_id = frames[i].id;
    raw[i].len = frames[i].length;
    std::copy_n(frames[i].data.begin(), frames[i].length, raw[i].data);
    io[i] = iovec{&raw[i], sizeof raw[i]};
    messages[i].msg_hdr.msg_iov = &io[i];
    messages[i].msg_hdr.msg_iovlen = 1;
  }
  for (;;) {
    const int n = ::sendmmsg(fd_.get(), messages.data(), static_cast<unsigned>(count),
                             MSG_DONTWAIT | MSG_NOSIGNAL);
    if (n > 0) {
      frames_sent_ += static_cast<std::uint64_t>(n);
      return static_cast<std::size_t>(n);
    }
    if (n == 0) return dh3::fail(BusError::io_error);
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

void SocketCanBus::handle_error_frame(std::uint32_t can_id, const std::uint8_t* data,
                                      TimePoint now) {
  ++error_frames_;
  const auto kinds = classify_error_frame(can_id, data);
  for (std::size_t i = 0; i < kErrorFrameKinds; ++i) {
    if (!kinds.test(i)) continue;
    const auto kind = static_cast<ErrorFrameKind>(i);
    const std::uint64_t total = error_kinds_[i].fetch_add(1, std::memory_order_relaxed) + 1;
    if (kind == ErrorFrameKind::bus_off || kind == ErrorFrameKind::restarted) continue;
    if (last_logged_[i] && now - *last_logged_[i] < kErrorLogInterval) continue;
    const auto level = (kind == ErrorFrameKind::error_active) ? spdlog::level::info
                                                               : spdlog::level::warn;
    spdlog::log(level, "{}: CAN error frame: {} ({} so far; controller status 0x{:02X}, "
                "protocol 0x{:02X}/0x{:02X}, tx/rx error counters {}/{})",
                spec_, to_string(kind), total, data[1], data[2], data[3], data[6], data[7]);
    last_logged_[i] = now;
  }
  if (kinds.test(index_of(ErrorFrameKind::bus_off)) && !bus_off_.exchange(true)) {
    spdlog::warn("{}: CAN controller is bus-off; nothing can be sent until it restarts "
                 "(automatic with `ip link set IF type can restart-ms 100`, or by hand with "
                 "`ip link set IF type can restart`)",
                 spec_);
    tracker_.mark_down("controller is bus-off", now);
  } else if (kinds.test(index_of(ErrorFrameKind::restarted))) {
    end_bus_off("controller restarted");
  }
}

void SocketCanBus::count_kernel_drops(std::uint32_t drops_so_far) {
  if (drops_so_far == kernel_drops_seen_) return;
  const std::uint32_t dropped = drops_so_far - kernel_drops_seen_;  // wraps like the kernel's
  kernel_drops_seen_ = drops_so_far;
  const std::uint64_t total =
      rx_overflow_drops_.fetch_add(dropped, std::memory_order_relaxed) + dropped;
  spdlog::warn("{}: receive queue overflowed: the kernel dropped {} frames ({} in all); the bus "
               "carries more than the service reads",
               spec_, dropped, total);
}

void SocketCanBus::read_available(std::vector<CanFrame>& out, TimePoint now) {
  for (int i = 0; i < kMaxFramesPerReceive; ++i) {
    // Room for a CAN FD frame, so an oversized datagram shows up as such
    // instead of being silently cut to the classic size.
    canfd_frame raw{};
    iovec io{&raw, sizeof raw};
    alignas(cmsghdr) std::array<char, CMSG_SPACE(sizeof(std::uint32_t)) +
                                          CMSG_SPACE(sizeof(timespec))>
        control{};
    msghdr message{};
    message.msg_iov = &io;
    message.msg_iovlen = 1;
    message.msg_control = control.data();
    message.msg_controllen = control.size();
    const ssize_t n = ::recvmsg(fd_.get(), &message, MSG_DONTWAIT);
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
    for (cmsghdr* c = CMSG_FIRSTHDR(&message); c != nullptr; c = CMSG_NXTHDR(&message, c)) {
      if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_RXQ_OVFL) {
        std::uint32_t drops = 0;
        std::memcpy(&drops, CMSG_DATA(c), sizeof drops);
        count_kernel_drops(drops);
      }
    }
    if (n != static_cast<ssize_t>(sizeof(can_frame))) {
      frames_ignored_.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    if ((raw.can_id & CAN_ERR_FLAG) != 0) {
      handle_error_frame(raw.can_id & CAN_ERR_MASK, raw.data, now);
      continue;
    }
    const std::uint32_t id = raw.can_id & CAN_SFF_MASK;
    if ((raw.can_id & (CAN_EFF_FLAG | CAN_RTR_FLAG)) != 0 || id > kMaxHandCanId ||
        raw.len > CAN_MAX_DLEN) {
      frames_ignored_.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    // A controller that delivers frames is on the bus again, even if its
    // restart report was lost (the queue may have overflowed).
    if (bus_off_.load()) end_bus_off("frames arrive again");
    CanFrame frame;
    frame.id = id;
    frame.length = raw.len;
    std::copy_n(raw.data, raw.len, frame.data.begin());
    out.push_back(frame);
    ++frames_received_;
    if (options_.receive_timestamps) {
      receive_times_.push_back(WallTime(std::chrono::duration_cast<WallTime::duration>(
          arrival_time(receive_timestamp(message)))));
    }
  }
}

Result<void, BusError> SocketCanBus::receive(std::vector<CanFrame>& out, Duration timeout) {
  const std::size_t frames_before = out.size();
  receive_times_.clear();
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

  if (can_carry_frames() || out.size() > frames_before) return {};
  return dh3::fail(BusError::link_down);
}

}  // namespace dh3::bus
