// Group requests: checked all or none, submitted to every member's bus with
// one GroupRelease, answered once when the last member ends.

#include "group_commands.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <memory>
#include <mutex>

#include "conversions.hpp"
#include "dh3/hand/group_release.hpp"

namespace dh3::dds {

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

}  // namespace

void summarize_group(msg::GroupReply& reply) {
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

/// One group's results, filled in by its members' completions on the bus loops.
struct GroupCommands::Pending {
  std::mutex mutex;
  msg::GroupReply reply;       ///< under mutex
  std::size_t remaining = 0;   ///< under mutex
  ClientShare::Ticket ticket;  ///< under mutex; freed when the reply goes
};

void GroupCommands::handle(msg::GroupRequest& request, const Caller& caller, bool stopping) {
  const std::string& name = parts_.options.name;
  if (!request.service().empty() && request.service() != name) return;
  msg::GroupReply reply;
  reply.client_id(request.client_id());
  reply.request_seq(request.request_seq());
  reply.command(request.command());
  for (const auto& hand : request.hands()) {
    msg::GroupMemberResult& member = reply.results().emplace_back();
    member.hand(hand);
    member.hand().service(name);
  }
  spdlog::debug("group request {}#{} of participant {}: {} to {} hands, value {}",
                request.client_id(), request.request_seq(), caller.id,
                command_name(request.command()), request.hands().size(), request.value());
  if (stopping) {
    refuse(reply, GroupRefusal{{}, Rejection{msg::CANCELLED, "the service is shutting down"}});
    return;
  }
  // Before the checks, as for a single request: a group refused at once
  // costs a reply too, and its members' checks cost more.
  if (auto admitted = parts_.rate.admit(caller.id, caller.shown_as); !admitted) {
    refuse(reply, GroupRefusal{{}, Rejection{msg::BUSY, std::move(admitted).error()}});
    return;
  }
  const std::string client_id = request.client_id();
  auto valid =
      validate_group(request, parts_.directory, [&](std::uint16_t bus, std::uint8_t can_id) {
        return member_facts(bus, can_id, caller, client_id);
      });
  if (!valid) {
    refuse(reply, valid.error());
    return;
  }
  auto ticket = parts_.share.admit(caller.id, caller.shown_as);
  if (!ticket) {
    refuse(reply, GroupRefusal{{}, Rejection{msg::BUSY, std::move(ticket).error()}});
    return;
  }
  const Duration timeout = request.timeout_ms() != 0
                               ? Duration(std::chrono::milliseconds(request.timeout_ms()))
                               : kDefaultGroupReadyTimeout;
  submit(*valid, std::move(reply), timeout, std::move(ticket).value());
}

MemberFacts GroupCommands::member_facts(std::uint16_t bus, std::uint8_t can_id,
                                        const Caller& caller, const std::string& client_id) const {
  MemberFacts facts;
  hand::BusScheduler& scheduler = *parts_.schedulers[bus];
  facts.link_up = scheduler.link_state() == bus::LinkState::up;
  for (const hand::HandState& state : scheduler.roster().published()) {
    if (state.can_id != can_id) continue;
    facts.online = state.online;
    facts.initialized = state.initialized;
  }
  facts.lease_blocker = parts_.leases.blocking_holder(HandKey{bus, can_id}, caller.id);
  facts.client_id_names_blocker =
      facts.lease_blocker && parts_.leases.held_by(HandKey{bus, can_id}, client_id);
  return facts;
}

void GroupCommands::refuse(msg::GroupReply& reply, const GroupRefusal& refusal) {
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
  summarize_group(reply);
  if (refusal.whole) {
    reply.code(refusal.whole->code);
    reply.message(refusal.whole->message);
  } else {
    reply.message("group refused, nothing sent: " + reply.message());
  }
  parts_.replies.write(reply);
}

void GroupCommands::submit(const std::vector<ValidRequest>& members, msg::GroupReply reply,
                           Duration timeout, ClientShare::Ticket ticket) {
  bool several_buses = false;
  for (const ValidRequest& member : members) several_buses |= member.bus != members.front().bus;
  auto group = std::make_shared<hand::GroupRelease>(
      members.size(), several_buses ? kCrossBusLead : Duration{}, parts_.clock.now() + timeout);
  auto pending = std::make_shared<Pending>();
  pending->reply = std::move(reply);
  pending->remaining = members.size();
  pending->ticket = std::move(ticket);
  for (std::size_t i = 0; i < members.size(); ++i) {
    hand::Command command = members[i].command;
    command.group = group;
    const std::uint16_t bus = members[i].bus;
    const std::uint8_t can_id = members[i].can_id;
    // Each member may complete at once (on this thread) or on its bus loop.
    parts_.schedulers[bus]->submit(
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
                                               parts_.directory.bus_name(bus), can_id);
            if (const std::string abandoned = group->abandoned_because();
                r.error() == hand::CommandError::cancelled && !abandoned.empty()) {
              why += " (the group was abandoned: " + abandoned + ")";
            }
            member.message(std::move(why));
          }
          if (--pending->remaining > 0) return;
          summarize_group(pending->reply);
          msg::GroupReply done = std::move(pending->reply);
          // Free before the reply goes: its client may send the next at once.
          pending->ticket = {};
          lock.unlock();
          parts_.replies.write(done);
        });
  }
}

}  // namespace dh3::dds
