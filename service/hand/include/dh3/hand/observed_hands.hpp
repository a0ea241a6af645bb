#pragma once
// What a standby knows of the hands on a bus another service drives, read from
// the frames it sees there: that service's requests and the hands' replies
// (on SocketCAN every socket on the interface sees both; StandbyBus). Kept as
// the active service's drivers keep it (HandState), so that a takeover starts
// from it: initialized hands stay initialized, motions in progress go on.
//
// Request or reply: both carry the hand's CAN ID, and an echo carries the
// request's very bytes, so a frame is told by its order (docs/protocol-notes.md
// reading 1): the first frame of a (hand, register) is a request and the next
// one within `reply_window` its reply. The active service keeps one frame in
// flight per hand, so this pairing holds (a frame the hand sends by itself
// beside it is paired apart, by its register). A read frame with a value in it is
// always a reply. The 0x0802 frame a hand sends by itself when initialization
// finished (reading 3) is taken as a request that changes nothing; the active
// service confirms it with a read whose reply is seen.
//
// Single-threaded: the standby's bus loop owns it.

#include <array>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <vector>

#include "dh3/base/clock.hpp"
#include "dh3/bus/bus.hpp"
#include "dh3/hand/hand_roster.hpp"
#include "dh3/hand/hand_types.hpp"
#include "dh3/protocol/codec.hpp"

namespace dh3::hand {

enum class FrameRole : std::uint8_t {
  request,      ///< sent by the active service
  reply,        ///< the hand's answer to the request seen before it
  undecodable,  ///< no DH-3 message (other traffic on the line)
};

/// A write the active service sent to a hand: a command's frame.
struct ObservedWrite {
  protocol::Message request;
  TimePoint sent_at{};
  bool echoed = false;  ///< the hand's echo was seen: the hand took it
};

class ObservedHands {
 public:
  /// `configured`: the hands the bus lists (others are added when they answer).
  /// `reply_window`: how long after a request its reply may come (the active
  /// service's reply timeout).
  ObservedHands(const std::vector<HandConfig>& configured, Duration reply_window);
  ~ObservedHands();
  ObservedHands(const ObservedHands&) = delete;
  ObservedHands& operator=(const ObservedHands&) = delete;

  /// One frame seen on the bus at `now`.
  FrameRole on_frame(const bus::CanFrame& frame, TimePoint now);

  /// Every hand configured or seen answering, by CAN ID.
  [[nodiscard]] std::vector<HandState> states() const;
  [[nodiscard]] std::optional<HandState> state(std::uint8_t can_id) const;
  /// The writes seen to a hand, oldest first (the last kWritesKept).
  [[nodiscard]] const std::deque<ObservedWrite>& writes(std::uint8_t can_id) const;
  /// The targets of the motions the active service started and no status
  /// has ended yet.
  [[nodiscard]] std::optional<std::int32_t> finger_motion(std::uint8_t can_id) const;
  [[nodiscard]] std::optional<std::int32_t> rotation_motion(std::uint8_t can_id) const;
  /// Requests seen so far (the active service's frames).
  [[nodiscard]] std::uint64_t requests_seen() const { return requests_seen_; }

  static constexpr std::size_t kWritesKept = 16;

 private:
  /// One hand's record (observed_hands.cpp: it holds the driver's motion types).
  struct Hand;

  void on_request(Hand& hand, const protocol::Message& request, TimePoint now);
  /// `answered`: it pairs with a request seen before it.
  void on_reply(Hand& hand, const protocol::Message& reply, bool answered, TimePoint now);
  void on_echo(Hand& hand, const protocol::Message& echo);
  void on_read(Hand& hand, const protocol::Message& reply);
  void on_grip_status(Hand& hand, std::int32_t status);
  void on_rotation_status(Hand& hand, std::int32_t status);

  Duration reply_window_;
  std::unique_ptr<std::array<Hand, 256>> hands_;
  std::uint64_t requests_seen_ = 0;
};

}  // namespace dh3::hand
