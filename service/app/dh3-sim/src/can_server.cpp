#include "dh3/sim_server/can_server.hpp"

#include <linux/can.h>
#include <spdlog/spdlog.h>
#include <sys/time.h>

#include <algorithm>
#include <cerrno>
#include <ctime>

#include "dh3/bus/receive_timestamp.hpp"
#include "dh3/protocol/codec.hpp"

namespace dh3::sim {

namespace {

// One round reads at most this many frames so a flooded bus cannot keep the
// loop from the hands' own frames and the control channel.
constexpr int kMaxFramesPerRound = 256;

}  // namespace

CanServer::CanServer(CanServerOptions options, bus::CanSocketOpener opener, const Clock& clock)
    : options_(std::move(options)), opener_(std::move(opener)), host_(options_, clock) {}

Result<std::unique_ptr<CanServer>, std::string> CanServer::open(CanServerOptions options,
                                                                bus::CanSocketOpener opener,
                                                                const Clock& clock) {
  std::unique_ptr<CanServer> server(new CanServer(std::move(options), std::move(opener), clock));
  if (auto started = server->host_.start(); !started) {
    return fail("cannot create a pipe: " + started.error());
  }
  if (auto opened = server->open_fd(); !opened) return fail(opened.error());
  return server;
}

Result<void, std::string> CanServer::open_fd() {
  auto opened = opener_();
  if (!opened) return fail(opened.error());
  fd_ = std::move(opened.value());
  set_nonblocking(fd_.get());
  if (options_.kernel_timestamps) {
    if (const auto refused = bus::enable_receive_timestamps(fd_.get())) {
      spdlog::warn(
          "dh3-sim: {}: no kernel receive timestamps ({}); the interval check uses "
          "the time of reading",
          options_.interface_name, errno_text(*refused));
    }
  }
  return {};
}

void CanServer::run() {
  spdlog::info("dh3-sim: serving {} hand(s) on {}", host_.hand_count(), options_.interface_name);
  host_.run(*this);
}

void CanServer::add_poll_fds(std::vector<pollfd>& fds) {
  if (fd_) fds.push_back(pollfd{fd_.get(), POLLIN, 0});
}

void CanServer::on_poll(std::span<const pollfd> fds) {
  if (!fds.empty() && fds[0].fd == fd_.get() && fds[0].revents != 0) read_frames();
}

void CanServer::read_frames() {
  for (int round = 0; round < kMaxFramesPerRound && fd_.valid(); ++round) {
    // Room for a CAN FD frame too, so a longer datagram is seen as such.
    alignas(can_frame) unsigned char data[sizeof(canfd_frame)];
    const bus::StampedRead read = bus::read_stamped(fd_.get(), data, MSG_DONTWAIT);
    if (read.got < 0) {
      if (read.error == EINTR) continue;
      if (read.error == EAGAIN || read.error == EWOULDBLOCK) return;
      handle_error(read.error, "receive");
      return;
    }
    if (read.got == 0) {
      // A datagram socket reads 0 only when its peer (a socketpair's) closed.
      lose_fd("the other end closed");
      return;
    }
    note_working();
    handle_frame(
        data, read.truncated ? sizeof data + 1 : static_cast<std::size_t>(read.got),
        options_.kernel_timestamps ? std::optional(bus::arrival_time(read.stamp)) : std::nullopt);
  }
}

void CanServer::handle_frame(const void* data, std::size_t size, std::optional<Duration> received) {
  can_frame frame{};
  if (size != sizeof frame) {
    ++counters_.foreign_frames;
    spdlog::debug("dh3-sim: {}: ignored a {}-byte datagram (no classic CAN frame)",
                  options_.interface_name, size);
    return;
  }
  std::copy_n(static_cast<const unsigned char*>(data), sizeof frame,
              reinterpret_cast<unsigned char*>(&frame));
  const bool standard_data = (frame.can_id & (CAN_EFF_FLAG | CAN_RTR_FLAG | CAN_ERR_FLAG)) == 0;
  const canid_t id = frame.can_id & CAN_EFF_MASK;
  std::optional<protocol::Message> request;
  if (standard_data && id <= bus::kMaxHandCanId && frame.len == protocol::kPayloadSize) {
    auto decoded = protocol::decode_payload(static_cast<std::uint8_t>(id),
                                            std::span(frame.data, protocol::kPayloadSize));
    if (decoded) request = decoded.value();
  }
  if (!request) {
    ++counters_.foreign_frames;
    spdlog::debug("dh3-sim: {}: ignored frame id 0x{:X} length {} (not a DH-3 request)",
                  options_.interface_name, frame.can_id, frame.len);
    return;
  }
  ++counters_.frames_received;
  host_.receive(*request, kEveryPeer, received);
}

void CanServer::send(std::uint64_t /*destination*/, const protocol::Message& message) {
  // On a bus every node sees every frame: there is one destination.
  if (!fd_) {
    ++counters_.frames_lost;
    return;
  }
  can_frame frame{};
  frame.can_id = message.hand_id;
  frame.len = protocol::kPayloadSize;
  const protocol::Payload payload = protocol::encode_payload(message);
  std::copy(payload.begin(), payload.end(), frame.data);
  for (;;) {
    const ssize_t sent = ::send(fd_.get(), &frame, sizeof frame, MSG_DONTWAIT | MSG_NOSIGNAL);
    if (sent == static_cast<ssize_t>(sizeof frame)) {
      ++counters_.frames_sent;
      note_working();
      return;
    }
    if (sent < 0 && errno == EINTR) continue;
    ++counters_.frames_lost;
    if (sent >= 0) {
      spdlog::warn("dh3-sim: {}: a frame was cut", options_.interface_name);
    } else if (errno == EAGAIN || errno == EWOULDBLOCK || errno == ENOBUFS) {
      // A hand's controller would retry; the interface's queue being full
      // means the bus is flooded, and a lost reply is what the service sees then.
      spdlog::warn("dh3-sim: {}: transmit queue full, {} lost", options_.interface_name,
                   protocol::describe(message));
    } else {
      handle_error(errno, "send");
    }
    return;
  }
}

void CanServer::handle_error(int error, std::string_view during) {
  if (error == ENETDOWN) {
    if (!down_reported_) {
      spdlog::warn("dh3-sim: {} is down; the hands wait for it", options_.interface_name);
      down_reported_ = true;
    }
    return;
  }
  lose_fd(std::string(during) + ": " + errno_text(error));
}

void CanServer::note_working() {
  if (!down_reported_) return;
  down_reported_ = false;
  spdlog::info("dh3-sim: {} carries frames again", options_.interface_name);
}

void CanServer::lose_fd(std::string_view reason) {
  if (!fd_) return;
  fd_.reset();
  down_reported_ = false;
  next_reopen_ = host_.clock().now() + options_.reopen_interval;
  spdlog::warn(
      "dh3-sim: lost {} ({}); opening it again every {} ms", options_.interface_name, reason,
      std::chrono::duration_cast<std::chrono::milliseconds>(options_.reopen_interval).count());
}

std::optional<TimePoint> CanServer::next_timer() const {
  if (fd_) return std::nullopt;
  return next_reopen_;
}

void CanServer::on_timer(TimePoint now) {
  if (fd_) return;
  if (auto opened = open_fd(); !opened) {
    spdlog::debug("dh3-sim: {} not back yet: {}", options_.interface_name, opened.error());
    next_reopen_ = now + options_.reopen_interval;
    return;
  }
  ++counters_.reopens;
  spdlog::info("dh3-sim: serving {} hand(s) on {} again", host_.hand_count(),
               options_.interface_name);
}

}  // namespace dh3::sim
