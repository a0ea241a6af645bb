// PendingCalls: a command from call() to its reply, its deadline or the loss
// of its service.

#include "pending_calls.hpp"

#include <algorithm>

#include "conversions.hpp"
#include "dh3/contract/admin_commands.hpp"
#include "hand_lookup.hpp"

namespace dh3::detail {

bool PendingCalls::add(std::uint64_t seq, Call call) {
  const bool before_wake = call.deadline < next_wake_;
  calls_.emplace(seq, std::move(call));
  return before_wake;
}

PendingCalls::Call* PendingCalls::find(std::uint64_t seq) {
  const auto it = calls_.find(seq);
  return it == calls_.end() ? nullptr : &it->second;
}

std::optional<PendingCalls::Call> PendingCalls::take(std::uint64_t seq) {
  const auto it = calls_.find(seq);
  if (it == calls_.end()) return std::nullopt;
  Call call = std::move(it->second);
  calls_.erase(it);
  return call;
}

bool PendingCalls::Call::administrative() const {
  return !group && contract::is_administrative(request.command());
}

std::string PendingCalls::Call::what() const {
  if (group) return group->what;
  return command_name(request.command()) + " for " + hand.to_string();
}

bool PendingCalls::assign(const std::string& service, const std::string& incarnation,
                          bool group_ready, bool admin_ready) {
  bool any = false;
  for (auto& [seq, call] : calls_) {
    if (call.sent_to.empty() && call.hand.service == service && (group_ready || !call.group) &&
        (admin_ready || !call.administrative())) {
      call.sent_to = incarnation;
      to_write_.push_back(seq);
      any = true;
    }
  }
  return any;
}

PendingCalls::Write PendingCalls::write_of(std::uint64_t seq, const Call& call) {
  if (call.group) return {seq, Outgoing(call.group->request), call.sent_to};
  return {seq, Outgoing(call.request), call.sent_to};
}

std::optional<PendingCalls::Write> PendingCalls::next_to_write() {
  while (!to_write_.empty()) {
    const std::uint64_t seq = to_write_.front();
    to_write_.pop_front();
    if (const auto it = calls_.find(seq); it != calls_.end()) return write_of(seq, it->second);
  }
  return std::nullopt;
}

std::vector<PendingCalls::Completion> PendingCalls::end_sent_to(const std::string& incarnation,
                                                                const std::string& why) {
  std::vector<Completion> ended;
  if (incarnation.empty()) return ended;
  for (auto it = calls_.begin(); it != calls_.end();) {
    if (it->second.sent_to == incarnation) {
      ended.emplace_back(
          std::move(it->second.done),
          make_reply(Code::service_lost,
                     why + " while " + it->second.what() +
                         " was pending; it had been sent to that service, so it may or may "
                         "not have reached the hand"));
      it = calls_.erase(it);
    } else {
      ++it;
    }
  }
  return ended;
}

std::vector<PendingCalls::Completion> PendingCalls::end_all(const Reply& reply) {
  std::vector<Completion> ended;
  for (auto& [seq, call] : calls_) ended.emplace_back(std::move(call.done), reply);
  calls_.clear();
  to_write_.clear();
  return ended;
}

PendingCalls::Expiry PendingCalls::expire(Clock::time_point now) {
  Expiry out;
  for (auto it = calls_.begin(); it != calls_.end();) {
    if (it->second.deadline <= now) {
      out.expired.push_back(std::move(it->second));
      it = calls_.erase(it);
    } else {
      out.next = std::min(out.next, it->second.deadline);
      ++it;
    }
  }
  return out;
}

Reply PendingCalls::expired_reply(const Call& call, bool service_alive, int domain,
                                  const std::string& seen) {
  const auto& service = call.hand.service;
  const std::string and_seen = seen.empty() ? "" : "; " + seen;
  if (call.group) {
    if (!call.sent_to.empty()) {
      return make_reply(Code::no_reply, "no group reply within " + describe_duration(call.timeout));
    }
    return make_reply(Code::no_service, "service '" + service +
                                            "' with group commands not found in " +
                                            describe_duration(call.timeout) + and_seen);
  }
  const std::string what = call.what();
  const std::string within = " within " + describe_duration(call.timeout);
  if (!call.sent_to.empty()) {
    return make_reply(Code::no_reply,
                      "no reply from service '" + service + "' to " + what + within);
  }
  if (service_alive) {
    return make_reply(Code::no_service, "service '" + service +
                                            "' was found but did not become ready to take "
                                            "requests" +
                                            within + " (" + what + " not sent)" + and_seen);
  }
  return make_reply(Code::no_service, no_service_found(service, domain, call.timeout) + " (" +
                                          what + " not sent)" + and_seen);
}

void PendingCalls::tell_acknowledgment(std::vector<Completion>& expired,
                                       const std::function<bool()>& acknowledged) {
  const auto no_reply = [](const auto& call) { return call.second.code == Code::no_reply; };
  if (std::none_of(expired.begin(), expired.end(), no_reply)) return;
  // Per writer, not per sample (Fast DDS 2.9 has no per-sample ack status):
  // "acknowledged" is certain, "not acknowledged" may stem from another
  // request or another service's reader, so it only says "may not".
  const bool all_acknowledged = acknowledged();
  for (auto& call : expired) {
    if (!no_reply(call)) continue;
    call.second.message += all_acknowledged
                               ? "; the service acknowledged the request, so it may have run"
                               : "; the service has not acknowledged the request, so it may "
                                 "not have received it";
  }
}

}  // namespace dh3::detail
