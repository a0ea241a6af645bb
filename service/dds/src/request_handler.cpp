// Requests: validated, run as a hand command, a scan or a lease change, and
// answered with exactly one reply.

#include "request_handler.hpp"

#include <spdlog/spdlog.h>

#include <chrono>

#include "conversions.hpp"
#include "dh3/contract/admin_commands.hpp"
#include "expiry_timer.hpp"
#include "status_publisher.hpp"

namespace dh3::dds {

msg::CommandReply make_reply(const ReplyHeader& header, msg::ResultCode code, std::string message) {
  msg::CommandReply reply;
  reply.client_id(header.client_id);
  reply.request_seq(header.request_seq);
  reply.hand(header.hand);
  reply.command(header.command);
  reply.code(code);
  reply.message(std::move(message));
  return reply;
}

AdminAccess RequestHandler::admin_access(RequestTopic topic) const {
  if (!parts_.options.allow_admin) return AdminAccess::off;
  // Without access control a topic is anyone's to write, so it proves
  // nothing: allow_admin then lets whoever reaches the service.
  if (access_control_ && topic != RequestTopic::admin) return AdminAccess::elsewhere;
  return AdminAccess::allowed;
}

void RequestHandler::handle(msg::CommandRequest& request, const Caller& caller, bool stopping,
                            RequestTopic topic) {
  const std::string& service = request.hand().service();
  if (!service.empty() && service != parts_.options.name) return;  // another service's

  if (spdlog::should_log(spdlog::level::debug)) {
    spdlog::debug("request {}#{} of participant {}: {} {}/{} value {}", request.client_id(),
                  request.request_seq(), caller.id, command_name(request.command()),
                  request.hand().bus(), request.hand().can_id(), request.value());
  }
  if (stopping) {
    const ReplyHeader header{request.client_id(), request.request_seq(), request.hand(),
                             request.command()};
    auto reply =
        make_reply(header, msg::CANCELLED,
                   command_name(header.command) + " cancelled: the service is shutting down");
    parts_.replies.write(reply);
    return;
  }
  if (rate_ != nullptr) {
    if (auto admitted = rate_->admit(caller.id, caller.shown_as); !admitted) {
      const ReplyHeader header{request.client_id(), request.request_seq(), request.hand(),
                               request.command()};
      auto reply = make_reply(header, msg::BUSY, std::move(admitted).error());
      parts_.replies.write(reply);
      return;
    }
  }
  if (topic == RequestTopic::admin && !contract::is_administrative(request.command())) {
    // The admin topic carries nothing else, so that an admin identity's
    // grant of it is a grant of administration and no more.
    const ReplyHeader header{request.client_id(), request.request_seq(), request.hand(),
                             request.command()};
    auto reply = make_reply(header, msg::INVALID_ARGUMENT,
                            command_name(header.command) +
                                " is no administrative command: " + dh3::topics::ADMIN_REQUEST +
                                " takes only SET_CAN_ID and SET_BAUD_RATE; send it on " +
                                dh3::topics::COMMAND_REQUEST);
    parts_.replies.write(reply);
    return;
  }
  auto valid = validate_request(request, parts_.directory, admin_access(topic));
  // The request object is reused for the next sample: its strings move into the reply.
  ReplyHeader header{std::move(request.client_id()), request.request_seq(),
                     std::move(request.hand()), request.command()};
  if (!valid) {
    spdlog::debug("request {}#{} refused: {}", header.client_id, header.request_seq,
                  valid.error().message);
    auto reply = make_reply(header, valid.error().code, std::move(valid.error().message));
    parts_.replies.write(reply);
    return;
  }
  switch (valid->action) {
    case RequestAction::hand_command:
      submit_command(*valid, caller, std::move(header));
      break;
    case RequestAction::scan:
      start_scan(*valid, caller, std::move(header));
      break;
    case RequestAction::acquire_lease:
    case RequestAction::renew_lease:
    case RequestAction::release_lease:
      handle_lease(*valid, caller, header);
      break;
  }
}

void RequestHandler::submit_command(const ValidRequest& valid, const Caller& caller,
                                    ReplyHeader header) {
  if (valid.needs_lease) {
    const HandKey hand{valid.bus, valid.can_id};
    const auto holder = valid.can_id == 0
                            ? parts_.leases.blocking_holder_on_bus(valid.bus, caller.id)
                            : parts_.leases.blocking_holder(hand, caller.id);
    if (holder) {
      auto reply = make_reply(header, msg::DENIED,
                              lease_refusal(hand_text(header.hand.bus(), valid.can_id), *holder,
                                            "only it may send " + command_name(header.command),
                                            parts_.leases.held_by(hand, header.client_id)));
      reply.lease_holder(*holder);
      if (valid.can_id != 0) parts_.statuses.attach_to(reply, valid.bus, valid.can_id);
      parts_.replies.write(reply);
      return;
    }
  }
  auto ticket = take_slot(caller, header);
  if (!ticket) return;
  const std::uint8_t can_id = valid.can_id;
  const std::uint16_t bus = valid.bus;
  parts_.schedulers[bus]->submit(
      can_id, valid.command,
      [this, bus, can_id, header = std::move(header),
       ticket = std::move(*ticket)](const hand::CommandResult& result) mutable {
        // Free before the reply goes: its client may send the next at once.
        ticket = {};
        msg::CommandReply reply;
        if (result) {
          reply = make_reply(header, msg::OK);
          reply.value(result->value);
          reply.grasp(to_msg(result->grasp));
        } else {
          reply = make_reply(header, to_result_code(result.error()),
                             describe_failure(result.error(), header.command, header.hand.bus(),
                                              static_cast<std::uint8_t>(header.hand.can_id())));
        }
        // On the bus loop, before the batch's end: a state this command
        // changed is held, and this reply carries it before it is sent.
        if (can_id != 0) parts_.statuses.attach_to(reply, bus, can_id);
        parts_.replies.write(reply);
      });
}

std::optional<ClientShare::Ticket> RequestHandler::take_slot(const Caller& caller,
                                                             const ReplyHeader& header) {
  auto ticket = parts_.share.admit(caller.id, caller.shown_as);
  if (ticket) return std::move(ticket).value();
  auto reply = make_reply(header, msg::BUSY, std::move(ticket).error());
  parts_.replies.write(reply);
  return std::nullopt;
}

void RequestHandler::start_scan(const ValidRequest& valid, const Caller& caller,
                                ReplyHeader header) {
  auto ticket = take_slot(caller, header);
  if (!ticket) return;
  auto scan = std::make_shared<PendingScan>();
  scan->header = std::move(header);
  scan->ticket = std::move(*ticket);
  {
    std::lock_guard lock(scans_mutex_);
    scans_.push_back(scan);
  }
  parts_.schedulers[valid.bus]->request_scan([this, scan](const std::vector<std::uint8_t>& found) {
    finish_scan(scan, msg::OK, found, {});
  });
}

void RequestHandler::cancel_scans() {
  std::vector<std::shared_ptr<PendingScan>> scans;
  {
    std::lock_guard lock(scans_mutex_);
    scans.swap(scans_);
  }
  for (const auto& scan : scans) {
    finish_scan(scan, msg::CANCELLED, {}, "SCAN cancelled: the service is shutting down");
  }
}

void RequestHandler::finish_scan(const std::shared_ptr<PendingScan>& scan, msg::ResultCode code,
                                 const std::vector<std::uint8_t>& found, std::string message) {
  if (scan->answered.exchange(true)) return;
  {
    std::lock_guard lock(scans_mutex_);
    std::erase(scans_, scan);
  }
  scan->ticket = {};
  auto reply = make_reply(scan->header, code, std::move(message));
  reply.found_ids().assign(found.begin(), found.end());
  parts_.replies.write(reply);
}

void RequestHandler::handle_lease(const ValidRequest& valid, const Caller& caller,
                                  const ReplyHeader& header) {
  const HandKey hand{valid.bus, valid.can_id};
  LeaseAnswer answer;
  switch (valid.action) {
    case RequestAction::acquire_lease:
      answer = parts_.leases.acquire(hand, caller.id, valid.lease_ttl, caller.shown_as);
      break;
    case RequestAction::renew_lease:
      answer = parts_.leases.renew(hand, caller.id, valid.lease_ttl);
      break;
    default:
      answer = parts_.leases.release(hand, caller.id);
      break;
  }
  const std::string who = hand_text(header.hand.bus(), valid.can_id);
  msg::CommandReply reply;
  switch (answer.outcome) {
    case LeaseOutcome::granted:
      reply = make_reply(header, msg::OK);
      reply.value(static_cast<std::int32_t>(
          std::chrono::duration_cast<std::chrono::milliseconds>(valid.lease_ttl).count()));
      break;
    case LeaseOutcome::held_by_other:
      reply =
          make_reply(header, msg::DENIED,
                     lease_refusal(who, answer.holder, command_name(header.command) + " refused",
                                   parts_.leases.held_by(hand, header.client_id)));
      break;
    case LeaseOutcome::not_held:
      reply = make_reply(header, msg::DENIED,
                         "'" + caller.shown_as + "' holds no lease on " + who +
                             " (it expired or was released); use ACQUIRE_LEASE");
      break;
  }
  reply.lease_holder(answer.holder);
  if (answer.holder_changed) {
    spdlog::info("{}: lease {} by '{}' (participant {})", who,
                 valid.action == RequestAction::release_lease ? "released" : "taken",
                 caller.shown_as, caller.id);
    parts_.statuses.hold_republished(hand, reply);
  } else {
    parts_.statuses.attach_to(reply, hand.bus, hand.can_id);
  }
  parts_.replies.write(reply);
  parts_.statuses.send_held(hand.bus, hand.can_id);
  if (valid.action != RequestAction::release_lease) parts_.timer.wake();
}

}  // namespace dh3::dds
