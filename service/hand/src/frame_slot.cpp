// FrameSlot: one frame in flight per hand, its re-sends and its pacing.

#include "frame_slot.hpp"

#include <algorithm>

namespace dh3::hand {

FrameSlot::FrameSlot(Duration spacing, int max_retries, TimePoint now)
    : spacing_(spacing), max_retries_(max_retries), next_send_at_(now) {}

protocol::Message FrameSlot::send(protocol::Message message, Purpose purpose, TimePoint now,
                                  bool retryable, Duration reply_timeout) {
  in_flight_ = InFlight{message, purpose, now, now + reply_timeout, reply_timeout, 1, retryable};
  next_send_at_ = now + spacing_;
  return message;
}

std::optional<protocol::Message> FrameSlot::send_again(TimePoint now) {
  if (!resend_ || !clear_to_send(now)) return std::nullopt;
  InFlight again = *resend_;
  resend_.reset();
  again.sent = now;
  again.deadline = now + again.reply_timeout;
  in_flight_ = again;
  next_send_at_ = now + spacing_;
  return again.message;
}

void FrameSlot::left_at(TimePoint left) {
  if (in_flight_)
    in_flight_->deadline = std::max(in_flight_->deadline, left + in_flight_->reply_timeout);
}

void FrameSlot::unsend() {
  if (!in_flight_) return;
  resend_ = *in_flight_;
  next_send_at_ = in_flight_->sent;
  in_flight_.reset();
}

void FrameSlot::hold_sends_until(TimePoint until) {
  next_send_at_ = std::max(next_send_at_, until);
}

std::optional<InFlight> FrameSlot::take_answered(const protocol::Message& reply) {
  if (!in_flight_ || in_flight_->message.reg != reply.reg) return std::nullopt;
  std::optional<InFlight> sent = std::move(in_flight_);
  in_flight_.reset();
  return sent;
}

std::optional<FrameSlot::Expired> FrameSlot::expire(TimePoint now) {
  if (!in_flight_ || now < in_flight_->deadline) return std::nullopt;
  const InFlight lost = *in_flight_;
  in_flight_.reset();
  const bool resent = lost.retryable && lost.attempts <= max_retries_;
  if (resent) {
    InFlight again = lost;
    ++again.attempts;
    resend_ = again;
  }
  return Expired{lost, resent};
}

void FrameSlot::clear() {
  in_flight_.reset();
  resend_.reset();
}

}  // namespace dh3::hand
