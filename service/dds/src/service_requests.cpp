// Requests: each one taken from the request reader, validated, run (a hand
// command, a scan or a lease change) and answered with exactly one reply.

#include "service_impl.hpp"

namespace dh3::dds {
using contract::TopicRole;
using eprosima::fastrtps::types::ReturnCode_t;

// ---------------------------------------------------------------------------
// Requests

void Service::Impl::on_requests(fdds::DataReader& reader) {
  std::lock_guard lock(dispatch_mutex_);
  fdds::SampleInfo info;
  while (reader.take_next_sample(&request_, &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data) continue;
    if (options_.test_seam_tracer)
      options_.test_seam_tracer(TracePoint::request_taken, request_.request_seq());
    handle_request(request_);
  }
}

void Service::Impl::handle_request(msg::CommandRequest& request) {
  const std::string& service = request.hand().service();
  if (!service.empty() && service != options_.name) return;  // another service's

  if (spdlog::should_log(spdlog::level::debug)) {
    spdlog::debug("request {}#{}: {} {}/{} value {}", request.client_id(), request.request_seq(),
                  command_name(request.command()), request.hand().bus(), request.hand().can_id(),
                  request.value());
  }
  if (stopping_) {
    const ReplyHeader header{request.client_id(), request.request_seq(), request.hand(),
                             request.command()};
    auto reply =
        make_reply(header, msg::CANCELLED,
                   command_name(header.command) + " cancelled: the service is shutting down");
    write_reply(reply);
    return;
  }
  auto valid = validate_request(request, directory_, options_.allow_admin);
  // The request object is reused for the next sample: its strings move into the reply.
  ReplyHeader header{std::move(request.client_id()), request.request_seq(),
                     std::move(request.hand()), request.command()};
  if (!valid) {
    spdlog::debug("request {}#{} refused: {}", header.client_id, header.request_seq,
                  valid.error().message);
    auto reply = make_reply(header, valid.error().code, std::move(valid.error().message));
    write_reply(reply);
    return;
  }
  switch (valid->action) {
    case RequestAction::hand_command:
      submit_command(*valid, std::move(header));
      break;
    case RequestAction::scan:
      start_scan(*valid, std::move(header));
      break;
    case RequestAction::acquire_lease:
    case RequestAction::renew_lease:
    case RequestAction::release_lease:
      handle_lease(*valid, header);
      break;
  }
}

void Service::Impl::submit_command(const ValidRequest& valid, ReplyHeader header) {
  if (valid.needs_lease) {
    const auto holder =
        valid.can_id == 0
            ? leases_.blocking_holder_on_bus(valid.bus, header.client_id)
            : leases_.blocking_holder(HandKey{valid.bus, valid.can_id}, header.client_id);
    if (holder) {
      auto reply =
          make_reply(header, msg::DENIED,
                     hand_text(header.hand.bus(), valid.can_id) + " is leased by client '" +
                         *holder + "'; only it may send " + command_name(header.command));
      reply.lease_holder(*holder);
      if (valid.can_id != 0) attach_status(reply, valid.bus, valid.can_id);
      write_reply(reply);
      return;
    }
  }
  const std::uint8_t can_id = valid.can_id;
  const std::uint16_t bus = valid.bus;
  buses_[bus]->scheduler->submit(
      can_id, valid.command,
      [this, bus, can_id, header = std::move(header)](const hand::CommandResult& result) {
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
        if (can_id != 0) attach_status(reply, bus, can_id);
        write_reply(reply);
      });
}

void Service::Impl::start_scan(const ValidRequest& valid, ReplyHeader header) {
  auto scan = std::make_shared<PendingScan>();
  scan->header = std::move(header);
  {
    std::lock_guard lock(scans_mutex_);
    scans_.push_back(scan);
  }
  buses_[valid.bus]->scheduler->request_scan([this, scan](const std::vector<std::uint8_t>& found) {
    finish_scan(scan, msg::OK, found, {});
  });
}

void Service::Impl::finish_scan(const std::shared_ptr<PendingScan>& scan, msg::ResultCode code,
                                const std::vector<std::uint8_t>& found, std::string message) {
  if (scan->answered.exchange(true)) return;
  {
    std::lock_guard lock(scans_mutex_);
    std::erase(scans_, scan);
  }
  auto reply = make_reply(scan->header, code, std::move(message));
  reply.found_ids().assign(found.begin(), found.end());
  write_reply(reply);
}

void Service::Impl::handle_lease(const ValidRequest& valid, const ReplyHeader& header) {
  const HandKey hand{valid.bus, valid.can_id};
  LeaseAnswer answer;
  switch (valid.action) {
    case RequestAction::acquire_lease:
      answer = leases_.acquire(hand, header.client_id, valid.lease_ttl);
      break;
    case RequestAction::renew_lease:
      answer = leases_.renew(hand, header.client_id, valid.lease_ttl);
      break;
    default:
      answer = leases_.release(hand, header.client_id);
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
      reply = make_reply(header, msg::DENIED,
                         who + " is leased by client '" + answer.holder + "'; " +
                             command_name(header.command) + " refused");
      break;
    case LeaseOutcome::not_held:
      reply = make_reply(header, msg::DENIED,
                         "client '" + header.client_id + "' holds no lease on " + who +
                             " (it expired or was released); use ACQUIRE_LEASE");
      break;
  }
  reply.lease_holder(answer.holder);
  if (answer.holder_changed) {
    spdlog::info("{}: lease {} by '{}'", who,
                 valid.action == RequestAction::release_lease ? "released" : "taken",
                 header.client_id);
    hold_republished_status(hand, reply);
  } else {
    attach_status(reply, hand.bus, hand.can_id);
  }
  write_reply(reply);
  send_held_status(hand.bus, hand.can_id);
  if (valid.action != RequestAction::release_lease) wake_lease_timer();
}

void Service::Impl::write_reply(msg::CommandReply& reply) {
  if (reply.code() != msg::OK) {
    spdlog::debug("reply {}#{}: {} {}", reply.client_id(), reply.request_seq(),
                  result_code_name(reply.code()), reply.message());
  }
  if (reply_writer_ == nullptr) return;
  const std::uint64_t seq = reply.request_seq();
  const std::string client_id = reply.client_id();
  if (reply_gate_.admit(reply) == GateOutcome::held) {
    spdlog::debug("reply {}#{} held until the client's reply reader matches", client_id, seq);
    wake_lease_timer();  // its deadline may now be the timer's next
    return;
  }
  publish_reply(reply);
}

void Service::Impl::on_reply_reader(const std::string& client_id, bool matched) {
  for (auto& reply : reply_gate_.reader_matched(client_id, matched)) publish_reply(reply);
}

void Service::Impl::publish_reply(msg::CommandReply& reply) {
  if (options_.test_seam_tracer)
    options_.test_seam_tracer(TracePoint::reply_writing, reply.request_seq());
  if (!reply_writer_->write(&reply)) {
    spdlog::warn("could not publish the reply to {}#{}", reply.client_id(), reply.request_seq());
  }
  if (options_.test_seam_tracer)
    options_.test_seam_tracer(TracePoint::reply_written, reply.request_seq());
}

}  // namespace dh3::dds
