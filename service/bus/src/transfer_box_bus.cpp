#include "dh3/bus/transfer_box_bus.hpp"

#include <poll.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <utility>

#include "dh3/protocol/codec.hpp"

namespace dh3::bus {
namespace {

// One receive() reads at most this much, so a flooding peer cannot keep the
// I/O loop from its other work; the rest stays in the kernel for the next call.
constexpr std::size_t kMaxBytesPerReceive = 64 * 1024;

long long to_ms(Duration d) {
  return static_cast<long long>(std::chrono::duration_cast<std::chrono::milliseconds>(d).count());
}

}  // namespace

TransferBoxBus::TransferBoxBus(std::string spec, std::unique_ptr<StreamLink> link,
                               const Clock& clock, TransferBoxOptions options)
    : spec_(std::move(spec)),
      link_(std::move(link)),
      clock_(clock),
      options_(options),
      tracker_(spec_, options.reconnect) {
  start_attempt(clock_.now());
}

TransferBoxBus::Counters TransferBoxBus::counters() const {
  return Counters{tracker_.attempts(), tracker_.drops(), frames_sent_, frames_received_,
                  decoder_.bytes_skipped()};
}

void TransferBoxBus::start_attempt(TimePoint now) {
  tracker_.count_attempt();
  auto started = link_->start_open();
  if (!started) {
    go_down(started.error(), now);
    return;
  }
  fd_ = std::move(started.value().fd);
  if (started.value().in_progress) {
    phase_ = Phase::connecting;
    connect_deadline_ = now + options_.connect_timeout;
  } else {
    go_up();
  }
}

void TransferBoxBus::finish_connect(TimePoint now) {
  auto finished = link_->finish_open(fd_.get());
  if (finished) {
    go_up();
  } else {
    go_down(finished.error(), now);
  }
}

void TransferBoxBus::go_up() {
  phase_ = Phase::up;
  decoder_.reset();  // nothing from an earlier connection can complete a frame now
  tracker_.mark_up();
}

void TransferBoxBus::go_down(std::string_view reason, TimePoint now) {
  fd_.reset();
  phase_ = Phase::down;
  // Commands queued for a dead connection are stale; the hand layer times
  // them out and decides what to re-send.
  send_buffer_.clear();
  decoder_.reset();
  tracker_.mark_down(reason, now);
}

Result<void, BusError> TransferBoxBus::send(const CanFrame& frame) {
  if (frame.length != protocol::kPayloadSize || frame.id > 0xFF) {
    return dh3::fail(BusError::frame_invalid);
  }
  const auto message = protocol::decode_payload(static_cast<std::uint8_t>(frame.id), frame.data);
  if (!message) return dh3::fail(BusError::frame_invalid);
  if (phase_ != Phase::up) return dh3::fail(BusError::link_down);

  const TimePoint now = clock_.now();
  if (send_buffer_.size() + protocol::kBoxFrameSize > options_.send_buffer_limit) {
    if (!flush(now)) return dh3::fail(BusError::link_down);
    if (send_buffer_.size() + protocol::kBoxFrameSize > options_.send_buffer_limit) {
      return dh3::fail(BusError::would_block);
    }
  }
  const protocol::BoxFrame bytes = protocol::encode_box_frame(*message);
  send_buffer_.insert(send_buffer_.end(), bytes.begin(), bytes.end());
  if (!flush(now)) return dh3::fail(BusError::link_down);
  ++frames_sent_;
  return {};
}

bool TransferBoxBus::flush(TimePoint now) {
  std::size_t written = 0;
  while (written < send_buffer_.size()) {
    const ssize_t n =
        link_->write_some(fd_.get(), std::span<const std::uint8_t>(send_buffer_).subspan(written));
    if (n > 0) {
      written += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) break;  // rest goes on POLLOUT
    go_down(n == 0 ? std::string("write made no progress") : "write: " + errno_text(errno), now);
    return false;
  }
  send_buffer_.erase(send_buffer_.begin(),
                     send_buffer_.begin() + static_cast<std::ptrdiff_t>(written));
  return true;
}

void TransferBoxBus::read_available(std::vector<CanFrame>& out, TimePoint now) {
  std::array<std::uint8_t, 4096> buffer{};
  std::size_t total = 0;
  while (total < kMaxBytesPerReceive) {
    const ssize_t n = link_->read_some(fd_.get(), buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return;
    if (n <= 0) {
      go_down(n == 0 ? std::string("end of stream (peer closed or device hung up)")
                     : "read: " + errno_text(errno),
              now);
      return;
    }
    total += static_cast<std::size_t>(n);
    decoded_.clear();
    decoder_.feed(std::span<const std::uint8_t>(buffer.data(), static_cast<std::size_t>(n)),
                  decoded_);
    for (const protocol::Message& message : decoded_) {
      CanFrame frame;
      frame.id = message.hand_id;
      frame.length = protocol::kPayloadSize;
      frame.data = protocol::encode_payload(message);
      out.push_back(frame);
      ++frames_received_;
    }
  }
}

Result<void, BusError> TransferBoxBus::receive(std::vector<CanFrame>& out, Duration timeout) {
  const std::size_t frames_before = out.size();
  TimePoint now = clock_.now();
  if (phase_ == Phase::down && tracker_.retry_due(now)) start_attempt(now);

  std::array<pollfd, 2> fds{};
  fds[0] = pollfd{wake_.fd(), POLLIN, 0};
  std::size_t count = 1;
  Duration wait = std::max(timeout, Duration::zero());
  switch (phase_) {
    case Phase::down:
      wait = std::min(wait, tracker_.next_attempt_at() - now);
      break;
    case Phase::connecting:
      fds[1] = pollfd{fd_.get(), POLLOUT, 0};
      count = 2;
      wait = std::min(wait, connect_deadline_ - now);
      break;
    case Phase::up:
      fds[1] =
          pollfd{fd_.get(), static_cast<short>(POLLIN | (send_buffer_.empty() ? 0 : POLLOUT)), 0};
      count = 2;
      break;
  }
  if (poll_fds(std::span<pollfd>(fds.data(), count), wait) < 0) {
    return dh3::fail(BusError::io_error);  // only EINVAL/ENOMEM: nothing a retry fixes
  }
  if (fds[0].revents != 0) wake_.drain();

  now = clock_.now();
  if (phase_ == Phase::connecting) {
    if (fds[1].revents != 0) {
      finish_connect(now);
    } else if (now >= connect_deadline_) {
      go_down("connect timed out after " + std::to_string(to_ms(options_.connect_timeout)) + " ms",
              now);
    }
  } else if (phase_ == Phase::up && fds[1].revents != 0) {
    const bool still_up = (fds[1].revents & POLLOUT) == 0 || flush(now);
    if (still_up) read_available(out, now);
  } else if (phase_ == Phase::down && tracker_.retry_due(now)) {
    start_attempt(now);  // the backoff ran out during the wait
  }

  if (phase_ == Phase::up || out.size() > frames_before) return {};
  return dh3::fail(BusError::link_down);
}

}  // namespace dh3::bus
