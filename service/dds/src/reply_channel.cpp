// Replies: written at once, or held by their gate until the client's reply
// reader matches, its participant leaves, or the hold limit passes.

#include "reply_channel.hpp"

#include <fastrtps/rtps/common/Guid.h>
#include <spdlog/spdlog.h>

#include <cstdint>
#include <string>
#include <string_view>

#include "conversions.hpp"
#include "dh3/contract/participant.hpp"

namespace dh3::dds {

ReplyChannel::ReplyChannel(const Clock& clock, const RequestTracer& tracer,
                           std::function<void()> on_held)
    : tracer_(tracer),
      on_held_(std::move(on_held)),
      gate_(clock, kHoldLimit, kHoldCaps),
      group_gate_(clock, kHoldLimit, kHoldCaps) {}

void ReplyChannel::WriterListener::on_publication_matched(
    eprosima::fastdds::dds::DataWriter* /*writer*/,
    const eprosima::fastdds::dds::PublicationMatchedStatus& status) {
  const std::string client_id = contract::client_id_for(status.last_subscription_handle);
  const bool matched = status.current_count_change > 0;
  if (group_) {
    for (auto& reply : channel_.group_gate_.reader_matched(client_id, matched)) {
      channel_.publish(reply);
    }
  } else {
    for (auto& reply : channel_.gate_.reader_matched(client_id, matched)) channel_.publish(reply);
  }
}

void ReplyChannel::detach() {
  if (writer_ != nullptr) writer_->set_listener(nullptr);
  writer_ = nullptr;
  group_writer_ = nullptr;
}

/// Logged if not OK, then published, held by its gate until the client's
/// reader matches, or dropped when its writer is gone.
template <typename Reply>
void ReplyChannel::pass_through(Reply& reply, ReplyGate<Reply>& gate, bool has_writer,
                                std::string_view what) {
  if (reply.code() != msg::OK) {
    spdlog::debug("{} {}#{}: {} {}", what, reply.client_id(), reply.request_seq(),
                  result_code_name(reply.code()), reply.message());
  }
  if (!has_writer) return;
  const std::uint64_t seq = reply.request_seq();
  const std::string client_id = reply.client_id();
  const Admission admission = gate.admit(reply);
  if (admission.outcome == GateOutcome::pass) {
    publish(reply);
    return;
  }
  spdlog::debug("{} {}#{} held until the client's reader matches", what, client_id, seq);
  if (admission.dropped) log_dropped(*admission.dropped, what);
  on_held_();
}

void ReplyChannel::log_dropped(const DroppedReply& dropped, std::string_view what) {
  // Once per client: a flood would otherwise log a line per request.
  if (dropped.client_drops != 1) return;
  const HoldCaps& caps = kHoldCaps;
  if (dropped.over_total) {
    spdlog::warn(
        "{} {}#{} dropped: {} replies are held for clients whose reply readers have not "
        "matched, at most {}; the oldest of the client holding the most go (this client's "
        "further drops are not logged)",
        what, dropped.client_id, dropped.request_seq, caps.total, caps.total);
    return;
  }
  spdlog::warn(
      "{} {}#{} dropped: participant {} writes requests but no reply reader of it has "
      "matched; at most {} of its replies are held, the oldest go (its further drops are "
      "not logged)",
      what, dropped.client_id, dropped.request_seq, dropped.client_id, caps.per_client);
}

void ReplyChannel::write(msg::CommandReply& reply) {
  pass_through(reply, gate_, writer_ != nullptr, "reply");
}

void ReplyChannel::write(msg::GroupReply& reply) {
  pass_through(reply, group_gate_, group_writer_ != nullptr, "group reply");
}

void ReplyChannel::publish(msg::CommandReply& reply) {
  if (tracer_) tracer_(TracePoint::reply_writing, reply.request_seq());
  if (!writer_->write(&reply)) {
    spdlog::warn("could not publish the reply to {}#{}", reply.client_id(), reply.request_seq());
  }
  if (tracer_) tracer_(TracePoint::reply_written, reply.request_seq());
}

void ReplyChannel::publish(msg::GroupReply& reply) {
  if (group_writer_ == nullptr) return;
  if (!group_writer_->write(&reply)) {
    spdlog::warn("could not publish the group reply to {}#{}", reply.client_id(),
                 reply.request_seq());
  }
}

void ReplyChannel::participant_joined(const std::string& client_id) {
  gate_.participant_joined(client_id);
  group_gate_.participant_joined(client_id);
}

std::size_t ReplyChannel::participant_left(const std::string& client_id) {
  if (const std::size_t capped = gate_.dropped(client_id) + group_gate_.dropped(client_id)) {
    spdlog::info(
        "participant {} left; {} of its replies were dropped over the hold caps ({} "
        "in all so far)",
        client_id, capped, dropped_replies());
  }
  return gate_.participant_left(client_id) + group_gate_.participant_left(client_id);
}

std::size_t ReplyChannel::dropped_replies() const {
  return gate_.dropped() + group_gate_.dropped();
}

std::optional<TimePoint> ReplyChannel::next_expiry() const {
  auto next = gate_.next_expiry();
  if (const auto group_due = group_gate_.next_expiry();
      group_due && (!next || *group_due < *next)) {
    next = group_due;
  }
  return next;
}

void ReplyChannel::write_expired() {
  const auto limit_s = std::chrono::duration_cast<std::chrono::seconds>(kHoldLimit).count();
  for (auto& reply : gate_.expire()) {
    spdlog::warn("reply {}#{} written without its client's reply reader matched, after {} s",
                 reply.client_id(), reply.request_seq(), limit_s);
    publish(reply);
  }
  for (auto& reply : group_gate_.expire()) {
    spdlog::warn("group reply {}#{} written without its client's reader matched, after {} s",
                 reply.client_id(), reply.request_seq(), limit_s);
    publish(reply);
  }
}

void ReplyChannel::write_all_held() {
  for (auto& reply : gate_.take_all()) publish(reply);
  for (auto& reply : group_gate_.take_all()) publish(reply);
}

}  // namespace dh3::dds
