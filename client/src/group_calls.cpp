// GroupCalls: group requests made, and group replies read.

#include "group_calls.hpp"

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

}  // namespace

GroupReply GroupCalls::refused(Code code, std::string message) {
  GroupReply reply;
  reply.code = code;
  reply.message = std::move(message);
  return reply;
}

Result<msg::GroupRequest, GroupReply> GroupCalls::make_request(
    GroupCommand command, const std::vector<HandAddress>& hands, std::int32_t value,
    Timeout timeout) {
  if (hands.empty())
    return fail(refused(Code::invalid_argument, "a group names at least one hand"));
  // The service bounds each member's command by it (a single call's timeout
  // stays with the client), so refuse here what the service would.
  if (timeout.count() > static_cast<Timeout::rep>(limits::REQUEST_TIMEOUT_MAX_MS)) {
    return fail(refused(Code::invalid_argument, "a group's timeout is at most " +
                                                    std::to_string(limits::REQUEST_TIMEOUT_MAX_MS) +
                                                    " ms, not " + std::to_string(timeout.count()) +
                                                    " ms"));
  }
  msg::GroupRequest request;
  request.service(hands.front().service);
  request.command(to_msg(command));
  request.value(value);
  request.timeout_ms(static_cast<std::uint32_t>(timeout.count()));
  for (const HandAddress& hand : hands) {
    if (hand.service != hands.front().service) {
      return fail(refused(Code::invalid_argument,
                          "a group's hands are of one service: " + hand.to_string() +
                              " is not of '" + hands.front().service + "'"));
    }
    // The check a single command of this hand passes first.
    msg::CommandRequest single;
    single.hand(detail::to_msg(hand));
    single.command(request.command());
    single.value(value);
    if (auto valid = check_request(single); !valid) {
      return fail(refused(valid.error().code, hand.to_string() + ": " + valid.error().message));
    }
    request.hands().push_back(detail::to_msg(hand));
  }
  return request;
}

GroupReply GroupCalls::reply_of(const msg::GroupReply& reply) {
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

Result<PendingCalls::Call, GroupReply> GroupCalls::make_call(GroupCommand command,
                                                             const std::vector<HandAddress>& hands,
                                                             std::int32_t value, Timeout timeout,
                                                             std::chrono::milliseconds limit,
                                                             PendingCalls::GroupDone done) {
  auto request = make_request(command, hands, value, timeout);
  if (!request) return fail(std::move(request).error());
  PendingCalls::Call call;
  call.hand.service = request->service();
  call.timeout = limit;
  // Every end but the reply: the client's own code and message.
  call.done = [done](Reply reply) { done(refused(reply.code, std::move(reply.message))); };
  call.group = PendingCalls::Group{std::move(request).value(),
                                   "GROUP " + std::string(to_string(command)) + " of " +
                                       std::to_string(hands.size()) + " hand(s)",
                                   std::move(done)};
  return call;
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
