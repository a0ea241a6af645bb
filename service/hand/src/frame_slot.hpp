#pragma once
// Loop thread only: its driver asks and tells it; nothing else reaches it.
// Pure: it is told the time of each call; it reads no clock.
//
// The one frame a hand may have in flight, its re-send, and the pacing that
// keeps two frames to the hand at least the frame spacing apart
// (SchedulerOptions::frame_spacing(), docs/protocol-notes.md reading 9). A
// frame is in flight from send() until a reply matches it or its deadline
// passes; a retryable frame that timed out is re-sent up to max_retries times,
// before anything else the hand would send.

#include <optional>

#include "dh3/base/clock.hpp"
#include "dh3/protocol/codec.hpp"
#include "hand_driver_states.hpp"

namespace dh3::hand {

class FrameSlot {
 public:
  /// `spacing`: the least time between two frames to the hand; `max_retries`:
  /// re-sends of a retryable frame after a timeout. Nothing goes before `now`.
  FrameSlot(Duration spacing, int max_retries, TimePoint now);

  /// Nothing is in flight and the pacing lets a frame go at `now`.
  [[nodiscard]] bool clear_to_send(TimePoint now) const {
    return !in_flight_ && now >= next_send_at_;
  }
  /// The frame in flight, if any.
  [[nodiscard]] const InFlight* in_flight() const { return in_flight_ ? &*in_flight_ : nullptr; }
  /// A frame that timed out (or could not be sent) waits to go again.
  [[nodiscard]] bool has_resend() const { return resend_.has_value(); }
  /// The earliest time the pacing lets a frame go.
  [[nodiscard]] TimePoint paced_until() const { return next_send_at_; }

  /// Puts `message` in flight at `now` (the caller checked clear_to_send()).
  protocol::Message send(protocol::Message message, Purpose purpose, TimePoint now, bool retryable,
                         Duration reply_timeout);
  /// The waiting re-send, put in flight at `now` with a fresh deadline, if
  /// there is one and clear_to_send(now).
  [[nodiscard]] std::optional<protocol::Message> send_again(TimePoint now);
  /// The frame in flight left for the bus at `left`, later than the time it
  /// was put in flight with: its reply is awaited for the reply timeout from
  /// then, so a stall between the two (a loaded machine) does not shorten it.
  void left_at(TimePoint left);
  /// The frame just put in flight was not sent (the bus would block): it is
  /// the next re-send, and the pacing is as before it.
  void unsend();
  /// Sends nothing before `until` (pacing across senders); never shortens it.
  void hold_sends_until(TimePoint until);

  /// The frame in flight if `reply` answers it, which is then no longer in
  /// flight. A reply matches on (hand, function, sub-function): the caller
  /// gives only this hand's frames, and the read/write byte is not compared
  /// (docs/protocol-notes.md reading 1).
  [[nodiscard]] std::optional<InFlight> take_answered(const protocol::Message& reply);

  /// A frame whose deadline passed unanswered.
  struct Expired {
    InFlight lost;  ///< as it was sent (its attempts so far)
    bool resent;    ///< it waits to go again (retryable, retries left)
  };
  /// The frame in flight, if its deadline passed at `now`; it is no longer
  /// in flight, and is re-sent next if it may be.
  [[nodiscard]] std::optional<Expired> expire(TimePoint now);

  /// Forgets the frame in flight and the re-send (the link was lost); the
  /// pacing stays, so a returning hand still gets its interval.
  void clear();

 private:
  Duration spacing_;
  int max_retries_;
  std::optional<InFlight> in_flight_;
  std::optional<InFlight> resend_;  ///< timed out (or not sent), to be sent again
  TimePoint next_send_at_;
};

}  // namespace dh3::hand
