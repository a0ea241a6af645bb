// Pending calls: a command from call() to its reply, its deadline or the loss
// of its service; the io thread that writes every request and ends calls
// whose deadline passed.

#include <algorithm>

#include "client_core.hpp"
#include "client_endpoints.hpp"
#include "conversions.hpp"

namespace dh3::detail {

Result<void, Reply> ClientCore::check(const HandAddress& hand, msg::CommandType command,
                                      std::int32_t value) {
  msg::CommandRequest request;
  request.hand(to_msg(hand));
  request.command(command);
  request.value(value);
  return check_request(request);
}

void ClientCore::call(const HandAddress& hand, msg::CommandType command, std::int32_t value,
                      std::uint16_t register_code, Timeout timeout, Done done) {
  msg::CommandRequest request;
  request.hand(to_msg(hand));
  request.command(command);
  request.value(value);
  request.register_code(register_code);
  if (auto checked = check_request(request); !checked) {
    done(std::move(checked).error());
    return;
  }
  std::uint64_t seq = 0;
  bool write_now = false;
  bool kick = false;
  msg::CommandRequest to_send;
  {
    std::unique_lock lock(mutex_);
    if (closed_) {
      lock.unlock();
      done(make_reply(Code::not_connected, error_.empty() ? "the client was closed" : error_));
      return;
    }
    if (!can_command_) {
      lock.unlock();
      done(make_reply(Code::denied, denied_message_));
      return;
    }
    seq = ++last_seq_;
    request.client_id(client_id_);
    request.request_seq(seq);
    Pending pending;
    pending.hand = hand;
    pending.request = std::move(request);
    pending.timeout = effective(timeout);
    pending.deadline = Clock::now() + pending.timeout;
    pending.done = std::move(done);
    if (ready_locked(hand.service)) {
      pending.sent_to = services_.find(hand.service)->second.incarnation;
      // Written here, without waking the io thread, unless that could let it
      // overtake a request written or queued before it.
      if (to_write_.empty() && writes_in_flight_ == 0 && !t_on_dds_listener) {
        write_now = true;
        ++writes_in_flight_;
        to_send = pending.request;
      } else {
        to_write_.push_back(seq);
        kick = true;
      }
    }
    // The io thread must see this deadline if it comes before its next wake.
    if (pending.deadline < io_wake_at_) kick = true;
    if (kick) io_kick_ = true;
    pending_.emplace(seq, std::move(pending));
  }
  if (kick) io_wake_.notify_all();
  if (write_now) write_request(seq, to_send);
}

void ClientCore::write_request(std::uint64_t seq, const msg::CommandRequest& request) {
  // DataWriter::write takes a non-const sample.
  msg::CommandRequest sample = request;
  const bool written = dds_->request_writer->write(&sample);
  Done failed;
  {
    std::lock_guard lock(mutex_);
    --writes_in_flight_;
    if (written) {
      requests_written_.fetch_add(1, std::memory_order_relaxed);
    } else if (const auto it = pending_.find(seq); it != pending_.end()) {
      failed = std::move(it->second.done);
      pending_.erase(it);
    }
  }
  writes_done_.notify_all();
  if (failed) failed(make_reply(Code::not_connected, "could not publish the request"));
}

std::future<Reply> ClientCore::call(const HandAddress& hand, msg::CommandType command,
                                    std::int32_t value, std::uint16_t register_code,
                                    Timeout timeout) {
  auto promise = std::make_shared<std::promise<Reply>>();
  auto future = promise->get_future();
  call(hand, command, value, register_code, timeout,
       [promise](Reply reply) { promise->set_value(std::move(reply)); });
  return future;
}

void ClientCore::write_requests_locked(std::unique_lock<std::mutex>& lock) {
  while (!to_write_.empty() && !closed_) {
    const std::uint64_t seq = to_write_.front();
    to_write_.pop_front();
    const auto it = pending_.find(seq);
    // Ended meanwhile (service lost, reply, deadline): never send it, so a
    // command the caller was told failed does not run after all.
    if (it == pending_.end()) continue;
    const msg::CommandRequest request = it->second.request;
    ++writes_in_flight_;
    lock.unlock();
    write_request(seq, request);
    lock.lock();
  }
}

void ClientCore::io_loop() {
  std::unique_lock lock(mutex_);
  while (!closed_) {
    // Requests first: a deadline check must not end a call whose request was
    // about to go out.
    write_requests_locked(lock);
    if (closed_) break;

    const auto now = Clock::now();
    std::vector<std::pair<Done, Reply>> expired;
    auto next = Clock::time_point::max();
    for (auto it = pending_.begin(); it != pending_.end();) {
      if (it->second.deadline <= now) {
        expired.emplace_back(std::move(it->second.done), expired_locked(it->second));
        it = pending_.erase(it);
      } else {
        next = std::min(next, it->second.deadline);
        ++it;
      }
    }
    if (!expired.empty()) {
      lock.unlock();
      tell_acknowledgment(expired);
      for (auto& [done, reply] : expired) done(std::move(reply));
      lock.lock();
      continue;  // state may have changed while unlocked
    }
    io_kick_ = false;
    io_wake_at_ = next;
    const auto wake = [this] { return closed_ || io_kick_ || !to_write_.empty(); };
    if (next == Clock::time_point::max()) {
      io_wake_.wait(lock, wake);
    } else {
      io_wake_.wait_until(lock, next, wake);
    }
  }
}

Reply ClientCore::expired_locked(const Pending& pending) const {
  const auto& service = pending.hand.service;
  const std::string what =
      command_name(pending.request.command()) + " for " + pending.hand.to_string();
  const std::string within = " within " + describe_duration(pending.timeout);
  if (!pending.sent_to.empty()) {
    return make_reply(Code::no_reply,
                      "no reply from service '" + service + "' to " + what + within);
  }
  const auto it = services_.find(service);
  if (it != services_.end() && it->second.alive) {
    return make_reply(Code::no_service, "service '" + service +
                                            "' was found but did not become ready to take "
                                            "requests" +
                                            within + " (" + what + " not sent)");
  }
  return make_reply(Code::no_service, "no service '" + service + "' found on DDS domain " +
                                          std::to_string(options_.domain) + within + " (" + what +
                                          " not sent)");
}

void ClientCore::tell_acknowledgment(std::vector<std::pair<Done, Reply>>& expired) const {
  const auto no_reply = [](const auto& call) { return call.second.code == Code::no_reply; };
  if (std::none_of(expired.begin(), expired.end(), no_reply)) return;
  // Per writer, not per sample (Fast DDS 2.9 has no per-sample ack status):
  // "acknowledged" is certain, "not acknowledged" may stem from another
  // request or another service's reader, so it only says "may not".
  const bool acknowledged =
      dds_->request_writer->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(0, 0)) ==
      eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK;
  for (auto& call : expired) {
    if (!no_reply(call)) continue;
    call.second.message += acknowledged
                               ? "; the service acknowledged the request, so it may have run"
                               : "; the service has not acknowledged the request, so it may "
                                 "not have received it";
  }
}

void ClientCore::run(Actions& actions) {
  for (auto& [done, reply] : actions.completions) done(std::move(reply));
  actions.completions.clear();
  if (actions.wake_io) io_wake_.notify_all();
}

CommandTraffic ClientCore::command_traffic() const {
  CommandTraffic traffic;
  traffic.requests_written = requests_written_.load(std::memory_order_relaxed);
  traffic.own_replies = own_replies_.load(std::memory_order_relaxed);
  traffic.foreign_replies = foreign_replies_taken_.load(std::memory_order_relaxed);
  if (dds_ != nullptr && dds_->participant != nullptr) {
    traffic.foreign_replies +=
        dds_->participant->reply_filter_counts().rejected.load(std::memory_order_relaxed);
  }
  return traffic;
}

void ClientCore::on_reply(const msg::CommandReply& reply) {
  // The reply reader's filter keeps our client_id; checked again in case
  // Fast DDS refused the filtered topic and we read the plain one.
  if (reply.client_id() != client_id_) {
    foreign_replies_taken_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  own_replies_.fetch_add(1, std::memory_order_relaxed);
  Done done;
  {
    std::lock_guard lock(mutex_);
    const auto it = pending_.find(reply.request_seq());
    if (it == pending_.end() || it->second.request.command() != reply.command()) return;
    // The hand's status as the command left it, cached (and posted) before the
    // call ends; the same sample on the status topic is then not news.
    if (reply.status().update_seq() != 0 && !closed_ && !it->second.sent_to.empty() &&
        !reply.status().service().empty() &&
        followed(reply.status().service(), reply.status().bus())) {
      take_status_locked(it->second.sent_to, reply.status());
    }
    done = std::move(it->second.done);
    pending_.erase(it);
  }
  done(to_reply(reply));
}

}  // namespace dh3::detail
