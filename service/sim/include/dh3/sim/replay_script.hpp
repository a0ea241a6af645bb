#pragma once
// What the hands of a recorded bus said, arranged for replaying it: a candump
// log as the flight recorder writes it (every frame with its time and its
// direction, T for what the service sent, R for what it received) read into,
// per hand:
//
// - the replies to its writes, per register, in the recorded order;
// - its epochs: the time before its first write and after each write. Each
//   epoch holds the replies to the reads of that time, per register, in the
//   recorded order, and the frames the hand sent unasked (the initialization
//   feedback), with their offset from the write that began the epoch.
//
// A received frame answers the hand's last request when it names the same
// register (the service has one frame in flight per hand and matches replies on
// hand and register, docs/protocol-notes.md reading 1); any other is unasked.
// Pure: it is given the log's text.

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dh3/base/clock.hpp"
#include "dh3/base/result.hpp"
#include "dh3/bus/bus.hpp"
#include "dh3/protocol/codec.hpp"

namespace dh3::sim {

struct RecordedReply {
  protocol::Message message;
  Duration latency{};  ///< from the request to the reply, as recorded
};

struct RecordedUnasked {
  protocol::Message message;
  Duration offset{};  ///< from the start of its epoch
};

/// Replies per register (Register::code()), oldest first.
using ReplyQueues = std::map<std::uint16_t, std::vector<RecordedReply>>;

struct ReplayEpoch {
  ReplyQueues reads;
  std::vector<RecordedUnasked> unasked;
};

struct RecordedHand {
  std::uint8_t id = 0;
  ReplyQueues writes;
  std::vector<ReplayEpoch> epochs;  ///< [0] before the first write; never empty
};

class ReplayScript {
 public:
  /// Reads a log's text. Fails, naming the line, on a line that is not a
  /// candump frame, on frames without the T/R field (the replay must know who
  /// sent what) and on a log of several buses (replay one bus's file).
  /// Comments, frames hands never send and frames that are no DH-3 message
  /// are skipped and counted.
  [[nodiscard]] static Result<ReplayScript, std::string> parse(std::string_view text);

  /// By CAN ID; the hands that sent at least one frame.
  [[nodiscard]] const std::map<std::uint8_t, RecordedHand>& hands() const { return hands_; }
  /// The bus's name in the log.
  [[nodiscard]] const std::string& device() const { return device_; }
  [[nodiscard]] std::size_t frames() const { return frames_; }
  [[nodiscard]] std::size_t skipped() const { return skipped_; }

 private:
  /// The request a hand has in flight.
  struct InFlight {
    protocol::Register reg;
    protocol::Access access = protocol::Access::read;
    bus::WallTime sent{};
  };

  void add_request(const protocol::Message& request, bus::WallTime time);
  void add_received(const protocol::Message& message, bus::WallTime time);
  RecordedHand& hand(std::uint8_t id);
  /// Keeps only the hands that sent something.
  void drop_silent_hands();

  std::map<std::uint8_t, RecordedHand> hands_;
  std::map<std::uint8_t, InFlight> in_flight_;
  std::map<std::uint8_t, bus::WallTime> epoch_start_;
  std::map<std::uint8_t, bool> answered_;
  std::optional<bus::WallTime> first_time_;
  std::string device_;
  std::size_t frames_ = 0;
  std::size_t skipped_ = 0;
};

}  // namespace dh3::sim
