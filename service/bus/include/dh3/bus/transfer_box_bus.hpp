#pragma once
// The vendor's transfer box: DH-3 messages as 14-byte frames (FF FE FD FC id
// func sub rw reserve data[4] FB) over a byte stream, TCP or a serial line.
// send() turns a CanFrame into one frame; receive() feeds the bytes read into a
// protocol::StreamDecoder, which resynchronises on garbage, and hands back
// CanFrames. When the stream breaks (EOF, reset, unplugged device) the bus
// reports link_down and reconnects with backoff during later receive() calls.
// Nothing blocks: connects are non-blocking with a deadline, every wait is a
// bounded poll that wake() interrupts.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "dh3/base/fd_util.hpp"
#include "dh3/bus/bus.hpp"
#include "dh3/bus/link_tracker.hpp"
#include "dh3/bus/stream_link.hpp"
#include "dh3/protocol/stream_decoder.hpp"

namespace dh3::bus {

struct TransferBoxOptions {
  ReconnectOptions reconnect;
  /// A connect still pending after this counts as failed.
  Duration connect_timeout = std::chrono::seconds(2);
  /// Bytes send() may hold while the stream is not writable; when full, send()
  /// returns would_block. Unsent bytes are dropped when the link goes down.
  std::size_t send_buffer_limit = 64 * 14;
  /// The CAN bit rate behind the box, when the user knows it (bit_rate()).
  std::uint32_t can_bit_rate = 0;
};

class TransferBoxBus final : public Bus {
 public:
  /// Starts the first open attempt at once without waiting for it.
  TransferBoxBus(std::string spec, std::unique_ptr<StreamLink> link, const Clock& clock,
                 TransferBoxOptions options = {});

  [[nodiscard]] const std::string& spec() const override { return spec_; }
  /// frame_invalid for ids over 255 (the box's ID byte), lengths other than 8
  /// or a read/write byte other than 00/01 (the box frame cannot carry them).
  Result<void, BusError> send(const CanFrame& frame) override;
  /// Frames decoded before the link dropped are returned with success; the
  /// drop is reported by the next call.
  Result<void, BusError> receive(std::vector<CanFrame>& out, Duration timeout) override;
  void wake() override { wake_.wake(); }
  [[nodiscard]] LinkState link_state() const override { return tracker_.state(); }
  [[nodiscard]] std::uint32_t bit_rate() const override { return options_.can_bit_rate; }

  /// Diagnostics, read on the loop thread.
  struct Counters {
    std::uint64_t open_attempts = 0;
    std::uint64_t link_drops = 0;
    std::uint64_t frames_sent = 0;
    std::uint64_t frames_received = 0;
    std::uint64_t bytes_skipped = 0;  ///< garbage between frames, partial frames lost
  };
  [[nodiscard]] Counters counters() const;

 private:
  enum class Phase : std::uint8_t { down, connecting, up };

  void start_attempt(TimePoint now);
  void finish_connect(TimePoint now);
  void go_up();
  void go_down(std::string_view reason, TimePoint now);
  /// Writes what it can of the send buffer. False if the link went down.
  bool flush(TimePoint now);
  void read_available(std::vector<CanFrame>& out, TimePoint now);

  std::string spec_;
  std::unique_ptr<StreamLink> link_;
  const Clock& clock_;
  TransferBoxOptions options_;
  LinkTracker tracker_;
  WakeFd wake_;
  Phase phase_ = Phase::down;
  UniqueFd fd_;
  TimePoint connect_deadline_{};
  std::vector<std::uint8_t> send_buffer_;
  protocol::StreamDecoder decoder_;
  std::uint64_t frames_sent_ = 0;
  std::uint64_t frames_received_ = 0;
  std::vector<protocol::Message> decoded_;  // reused between reads
};

}  // namespace dh3::bus
