// Group requests: one command for several hands, all or none
// (group_validation.hpp), their motion frames released together by the hand
// layer (hand/group_release.hpp), one reply once every hand's command ended.

#include <fmt/format.h>

#include "dh3/hand/group_release.hpp"
#include "service_impl.hpp"

namespace dh3::dds {
using contract::TopicRole;
using eprosima::fastrtps::types::ReturnCode_t;

namespace {

/// The release lies this far after the last member got ready when the group
/// spans buses: the other buses' loops, woken then, wait for it rather than
/// send late. One bus needs none: its own next pass sends them all.
constexpr Duration kCrossBusLead = std::chrono::milliseconds(2);
/// How long the members may take to get ready (a grasp's force write, the
/// hands' intervals) when the request gives no timeout.
constexpr Duration kDefaultGroupReadyTimeout = std::chrono::seconds(5);

std::string member_text(const msg::HandAddress& hand) {
  return fmt::format("{}/{}", hand.bus(), hand.can_id());
}

/// Overall code and message: OK, or the first failed hand's code and every
/// failed hand's reason. Hands CANCELLED because another failed are named
/// only when no hand failed otherwise: the cause is the news.
void summarize(msg::GroupReply& reply) {
  bool root_cause = false;
  for (const auto& member : reply.results()) {
    root_cause |= member.code() != msg::OK && member.code() != msg::CANCELLED;
  }
  std::string message;
  reply.code(msg::OK);
  for (const auto& member : reply.results()) {
    if (member.code() == msg::OK || (root_cause && member.code() == msg::CANCELLED)) continue;
    if (reply.code() == msg::OK) reply.code(member.code());
    if (!message.empty()) message += "; ";
    message += fmt::format("{}: {}: {}", member_text(member.hand()),
                           result_code_name(member.code()), member.message());
  }
  reply.message(std::move(message));
}

}  // namespace

/// One group's results, filled in by its members' completions on the bus loops.
struct Service::Impl::PendingGroup {
  std::mutex mutex;
  msg::GroupReply reply;
  std::size_t remaining = 0;
};

void Service::Impl::create_group_endpoints() {
  group_reply_writer_ = participant_->publisher().create_datawriter(
      participant_->topics().group_reply, contract::writer_qos(TopicRole::reply),
      &group_reply_writer_listener_, fdds::StatusMask::publication_matched());
  auto qos = contract::reader_qos(TopicRole::request);
  qos.history().kind = fdds::KEEP_ALL_HISTORY_QOS;
  if (group_reply_writer_ != nullptr) {
    group_request_reader_ = participant_->subscriber().create_datareader(
        participant_->topics().group_request, qos, &group_request_listener_,
        fdds::StatusMask::data_available());
  }
  if (group_request_reader_ == nullptr) {
    spdlog::warn("group commands are off: {}",
                 cannot_create("the group request reader and reply writer"));
  }
}

void Service::Impl::on_group_requests(fdds::DataReader& reader) {
  std::lock_guard lock(dispatch_mutex_);
  fdds::SampleInfo info;
  while (reader.take_next_sample(&group_request_, &info) == ReturnCode_t::RETCODE_OK) {
    if (info.valid_data) handle_group(group_request_);
  }
}

void Service::Impl::handle_group(msg::GroupRequest& request) {
  if (!request.service().empty() && request.service() != options_.name) return;
  msg::GroupReply reply;
  reply.client_id(request.client_id());
  reply.request_seq(request.request_seq());
  reply.command(request.command());
  for (const auto& hand : request.hands()) {
    msg::GroupMemberResult& member = reply.results().emplace_back();
    member.hand(hand);
    member.hand().service(options_.name);
  }
  spdlog::debug("group request {}#{}: {} to {} hands, value {}", request.client_id(),
                request.request_seq(), command_name(request.command()), request.hands().size(),
                request.value());
  if (stopping_) {
    refuse_group(reply, GroupRefusal{{}, Rejection{msg::CANCELLED, "the service is shutting down"}});
    return;
  }
  const std::string client_id = request.client_id();
  auto valid = validate_group(request, directory_, [&](std::uint16_t bus, std::uint8_t can_id) {
    return member_facts(bus, can_id, client_id);
  });
  if (!valid) {
    refuse_group(reply, valid.error());
    return;
  }
  const Duration timeout = request.timeout_ms() != 0
                               ? Duration(std::chrono::milliseconds(request.timeout_ms()))
                               : kDefaultGroupReadyTimeout;
  submit_group(*valid, std::move(reply), timeout);
}

MemberFacts Service::Impl::member_facts(std::uint16_t bus, std::uint8_t can_id,
                                        const std::string& client_id) const {
  MemberFacts facts;
  const BusRuntime& runtime = *buses_[bus];
  facts.link_up = runtime.scheduler->link_state() == bus::LinkState::up;
  for (const hand::HandState& state : runtime.scheduler->roster().published()) {
    if (state.can_id != can_id) continue;
    facts.online = state.online;
    facts.initialized = state.initialized;
  }
  facts.lease_blocker = leases_.blocking_holder(HandKey{bus, can_id}, client_id);
  return facts;
}

void Service::Impl::refuse_group(msg::GroupReply& reply, const GroupRefusal& refusal) {
  auto& results = reply.results();
  for (auto& member : results) {
    member.code(msg::CANCELLED);
    member.message(refusal.whole ? refusal.whole->message
                                 : "nothing sent: another hand of the group failed its check");
  }
  for (const MemberRefusal& refused : refusal.members) {
    results[refused.index].code(refused.why.code);
    results[refused.index].message(refused.why.message);
  }
  summarize(reply);
  if (refusal.whole) {
    reply.code(refusal.whole->code);
    reply.message(refusal.whole->message);
  } else {
    reply.message("group refused, nothing sent: " + reply.message());
  }
  write_group_reply(reply);
}

void Service::Impl::submit_group(const std::vector<ValidRequest>& members, msg::GroupReply reply,
                                 Duration timeout) {
  bool several_buses = false;
  for (const ValidRequest& member : members) several_buses |= member.bus != members.front().bus;
  auto group = std::make_shared<hand::GroupRelease>(
      members.size(), several_buses ? kCrossBusLead : Duration{}, clock_.now() + timeout);
  auto pending = std::make_shared<PendingGroup>();
  pending->reply = std::move(reply);
  pending->remaining = members.size();
  for (std::size_t i = 0; i < members.size(); ++i) {
    hand::Command command = members[i].command;
    command.group = group;
    const std::uint16_t bus = members[i].bus;
    const std::uint8_t can_id = members[i].can_id;
    // Each member may complete at once (on this thread) or on its bus loop.
    buses_[bus]->scheduler->submit(
        can_id, std::move(command),
        [this, pending, group, i, bus, can_id](const hand::CommandResult& r) {
          std::unique_lock lock(pending->mutex);
          msg::GroupMemberResult& member = pending->reply.results()[i];
          if (r) {
            member.code(msg::OK);
            member.value(r->value);
            member.grasp(to_msg(r->grasp));
          } else {
            member.code(to_result_code(r.error()));
            std::string why = describe_failure(r.error(), pending->reply.command(),
                                               directory_.bus_name(bus), can_id);
            if (const std::string abandoned = group->abandoned_because();
                r.error() == hand::CommandError::cancelled && !abandoned.empty()) {
              why += " (the group was abandoned: " + abandoned + ")";
            }
            member.message(std::move(why));
          }
          if (--pending->remaining > 0) return;
          summarize(pending->reply);
          msg::GroupReply done = std::move(pending->reply);
          lock.unlock();
          write_group_reply(done);
        });
  }
}

void Service::Impl::write_group_reply(msg::GroupReply& reply) {
  if (reply.code() != msg::OK) {
    spdlog::debug("group reply {}#{}: {} {}", reply.client_id(), reply.request_seq(),
                  result_code_name(reply.code()), reply.message());
  }
  if (group_reply_writer_ == nullptr) return;
  const std::uint64_t seq = reply.request_seq();
  const std::string client_id = reply.client_id();
  if (group_reply_gate_.admit(reply) == GateOutcome::held) {
    spdlog::debug("group reply {}#{} held until the client's reader matches", client_id, seq);
    wake_lease_timer();  // its deadline may now be the timer's next
    return;
  }
  publish_group_reply(reply);
}

void Service::Impl::on_group_reply_reader(const std::string& client_id, bool matched) {
  for (auto& reply : group_reply_gate_.reader_matched(client_id, matched)) {
    publish_group_reply(reply);
  }
}

void Service::Impl::publish_group_reply(msg::GroupReply& reply) {
  if (group_reply_writer_ == nullptr) return;
  if (!group_reply_writer_->write(&reply)) {
    spdlog::warn("could not publish the group reply to {}#{}", reply.client_id(),
                 reply.request_seq());
  }
}

}  // namespace dh3::dds
