// Control leases: a client that leaves the domain loses its leases at once,
// the others end when their time runs out (the lease timer thread, which also
// writes the replies the reply gate held too long).

#include "service_impl.hpp"

namespace dh3::dds {
using contract::TopicRole;
using eprosima::fastrtps::types::ReturnCode_t;

// ---------------------------------------------------------------------------
// Leases

void Service::Impl::on_participant_left(const std::string& participant_id, bool dropped) {
  if (const std::size_t dropped_replies = reply_gate_.participant_left(participant_id) +
                                          group_reply_gate_.participant_left(participant_id)) {
    spdlog::info("{} held replies to {} dropped: it left before its reply reader matched",
                 dropped_replies, participant_id);
  }
  for (const auto& ended : leases_.drop_client(participant_id)) {
    spdlog::info("{}: lease of '{}' ended, its participant {} the domain",
                 hand_text(buses_[ended.hand.bus]->name, ended.hand.can_id), ended.holder,
                 dropped ? "dropped out of" : "left");
    republish_status(ended.hand);
  }
}

void Service::Impl::wake_lease_timer() {
  {
    std::lock_guard lock(lease_timer_mutex_);
    ++lease_timer_generation_;
  }
  lease_timer_cv_.notify_all();
}

void Service::Impl::lease_timer_loop() {
  std::unique_lock lock(lease_timer_mutex_);
  while (!lease_timer_stop_) {
    const std::uint64_t seen = lease_timer_generation_;
    const auto woken = [&] { return lease_timer_stop_ || lease_timer_generation_ != seen; };
    auto next = leases_.next_expiry();
    for (const auto reply_due : {reply_gate_.next_expiry(), group_reply_gate_.next_expiry()}) {
      if (reply_due && (!next || *reply_due < *next)) next = reply_due;
    }
    if (next) {
      // The lease table's and the gate's clock is the steady clock in a running service.
      lease_timer_cv_.wait_until(lock, *next, woken);
    } else {
      lease_timer_cv_.wait(lock, woken);
    }
    if (lease_timer_stop_) break;
    lock.unlock();
    for (auto& reply : reply_gate_.expire()) {
      spdlog::warn("reply {}#{} written without its client's reply reader matched, after {} s",
                   reply.client_id(), reply.request_seq(),
                   std::chrono::duration_cast<std::chrono::seconds>(kReplyHoldLimit).count());
      publish_reply(reply);
    }
    for (auto& reply : group_reply_gate_.expire()) {
      spdlog::warn("group reply {}#{} written without its client's reader matched, after {} s",
                   reply.client_id(), reply.request_seq(),
                   std::chrono::duration_cast<std::chrono::seconds>(kReplyHoldLimit).count());
      publish_group_reply(reply);
    }
    for (const auto& ended : leases_.expire()) {
      spdlog::info("{}: lease of '{}' expired",
                   hand_text(buses_[ended.hand.bus]->name, ended.hand.can_id), ended.holder);
      republish_status(ended.hand);
    }
    lock.lock();
  }
}

}  // namespace dh3::dds
