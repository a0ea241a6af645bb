// Group calls (dh3/group.hpp): one GroupRequest on its own topic, one
// GroupReply. Simpler than single calls (pending_calls.cpp) on purpose: the
// calling thread waits for the service's group endpoints, writes the request
// itself and waits for the reply; a reply that does not come by the deadline
// (the service lost included) ends the call NO_REPLY.

#include "client_core.hpp"
#include "client_endpoints.hpp"
#include "conversions.hpp"

namespace dh3::detail {
namespace {

msg::CommandType to_msg(GroupCommand command) {
  switch (command) {
    case GroupCommand::initialize:
      return msg::INITIALIZE;
    case GroupCommand::move:
      return msg::MOVE;
    case GroupCommand::rotate:
      return msg::ROTATE;
    case GroupCommand::grasp:
      return msg::GRASP;
    case GroupCommand::release:
      return msg::RELEASE;
    case GroupCommand::set_closing_force:
      return msg::SET_CLOSING_FORCE;
    case GroupCommand::set_opening_force:
      return msg::SET_OPENING_FORCE;
  }
  return msg::MOVE;
}

GroupReply refused(Code code, std::string message) {
  GroupReply reply;
  reply.code = code;
  reply.message = std::move(message);
  return reply;
}

GroupReply group_reply_of(const msg::GroupReply& reply) {
  GroupReply out;
  out.code = to_code(reply.code());
  out.message = reply.message();
  for (const auto& member : reply.results()) {
    GroupMemberReply& hand = out.hands.emplace_back();
    hand.hand = to_public(member.hand());
    hand.code = to_code(member.code());
    hand.message = member.message();
    hand.value = member.value();
    hand.grasp = to_public(member.grasp());
  }
  return out;
}

/// The request as it goes out, or why it cannot: the hands must be of one
/// service, and each must pass the contract's limits as a single command would.
Result<msg::GroupRequest, GroupReply> make_request(GroupCommand command,
                                                   const std::vector<HandAddress>& hands,
                                                   std::int32_t value, Timeout timeout) {
  if (hands.empty()) return fail(refused(Code::invalid_argument, "a group names at least one hand"));
  msg::GroupRequest request;
  request.service(hands.front().service);
  request.command(to_msg(command));
  request.value(value);
  request.timeout_ms(static_cast<std::uint32_t>(timeout.count()));
  for (const HandAddress& hand : hands) {
    if (hand.service != hands.front().service) {
      return fail(refused(Code::invalid_argument,
                          "a group's hands are of one service: " + hand.to_string() + " is not of '" +
                              hands.front().service + "'"));
    }
    if (auto valid = ClientCore::check(hand, request.command(), value); !valid) {
      return fail(refused(valid.error().code, hand.to_string() + ": " + valid.error().message));
    }
    request.hands().push_back(detail::to_msg(hand));
  }
  return request;
}

}  // namespace

bool ClientCore::group_ready_locked(const std::string& service) const {
  if (!ready_locked(service)) return false;
  const std::string& prefix = services_.find(service)->second.incarnation;
  return group_request_readers_.count(prefix) > 0 && group_reply_writers_.count(prefix) > 0;
}

GroupReply ClientCore::group_call(GroupCommand command, const std::vector<HandAddress>& hands,
                                  std::int32_t value, Timeout timeout) {
  const auto limit = effective(timeout);
  auto request = make_request(command, hands, value, timeout);
  if (!request) return std::move(request).error();
  if (!connected()) return refused(Code::not_connected, "the client is not connected");
  if (!can_command_ || dds_->group_request_writer == nullptr || dds_->group_reply_reader == nullptr)
    return refused(Code::denied, "not permitted to publish group requests");
  const auto deadline = Clock::now() + limit;
  const std::string& service = request->service();
  auto promise = std::make_shared<std::promise<GroupReply>>();
  auto future = promise->get_future();
  std::uint64_t seq = 0;
  {
    std::unique_lock lock(mutex_);
    if (!changed_.wait_until(lock, deadline,
                             [&] { return closed_ || group_ready_locked(service); })) {
      return refused(Code::no_service, "service '" + service + "' with group commands not found in " +
                                           describe_duration(limit));
    }
    if (closed_) return refused(Code::not_connected, "the client was closed");
    seq = ++last_seq_;
    group_pending_[seq] = promise;
    ++writes_in_flight_;
  }
  request->client_id(client_id_);
  request->request_seq(seq);
  const bool written = dds_->group_request_writer->write(&*request);
  {
    std::lock_guard lock(mutex_);
    --writes_in_flight_;
    if (written) requests_written_.fetch_add(1, std::memory_order_relaxed);
  }
  writes_done_.notify_all();
  if (written && future.wait_until(deadline) == std::future_status::ready) return future.get();
  {
    std::lock_guard lock(mutex_);
    // The reply may have come in between: it wins.
    if (group_pending_.erase(seq) == 0) return future.get();
  }
  if (!written) return refused(Code::not_connected, "could not publish the group request");
  return refused(Code::no_reply, "no group reply within " + describe_duration(limit));
}

void ClientCore::on_group_reply(const msg::GroupReply& reply) {
  if (reply.client_id() != client_id_) {
    foreign_replies_taken_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  std::shared_ptr<std::promise<GroupReply>> promise;
  {
    std::lock_guard lock(mutex_);
    const auto it = group_pending_.find(reply.request_seq());
    if (it == group_pending_.end()) return;
    promise = std::move(it->second);
    group_pending_.erase(it);
  }
  own_replies_.fetch_add(1, std::memory_order_relaxed);
  promise->set_value(group_reply_of(reply));
}

void ClientCore::on_group_request_reader_matched(const std::string& prefix, bool matched) {
  on_match(group_request_readers_, prefix, matched);
  changed_.notify_all();  // a group call may wait for it (group_ready_locked)
}

void ClientCore::on_group_reply_writer_matched(const std::string& prefix, bool matched) {
  on_match(group_reply_writers_, prefix, matched);
  changed_.notify_all();
}

void ClientCore::close_group_calls_locked() {
  for (auto& [seq, promise] : group_pending_) {
    promise->set_value(refused(Code::not_connected, "the client was closed"));
  }
  group_pending_.clear();
}

}  // namespace dh3::detail

namespace dh3 {

std::string_view to_string(GroupCommand command) {
  switch (command) {
    case GroupCommand::initialize:
      return "INITIALIZE";
    case GroupCommand::move:
      return "MOVE";
    case GroupCommand::rotate:
      return "ROTATE";
    case GroupCommand::grasp:
      return "GRASP";
    case GroupCommand::release:
      return "RELEASE";
    case GroupCommand::set_closing_force:
      return "SET_CLOSING_FORCE";
    case GroupCommand::set_opening_force:
      return "SET_OPENING_FORCE";
  }
  return "?";
}

}  // namespace dh3
