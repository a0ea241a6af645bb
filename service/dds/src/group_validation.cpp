#include "group_validation.hpp"

#include <set>
#include <utility>

#include "conversions.hpp"
#include "dh3/hand/command_validation.hpp"

namespace dh3::dds {
namespace {

std::string who(const msg::HandAddress& hand) {
  return "hand " + std::to_string(hand.can_id()) + " on bus '" + hand.bus() + "'";
}

/// What a single request to the member would be.
msg::CommandRequest member_request(const msg::GroupRequest& group, const msg::HandAddress& hand) {
  msg::CommandRequest request;
  request.client_id(group.client_id());
  request.request_seq(group.request_seq());
  request.hand(hand);
  request.command(group.command());
  request.value(group.value());
  request.timeout_ms(group.timeout_ms());
  return request;
}

/// The checks a bus would only make later; nullopt if the hand passes.
std::optional<Rejection> check_facts(const ValidRequest& valid, const msg::HandAddress& hand,
                                     const MemberFacts& facts, msg::CommandType command) {
  if (!facts.link_up) return Rejection{msg::BUS_DOWN, "bus '" + hand.bus() + "' is down"};
  if (!facts.online) return Rejection{msg::TIMEOUT, who(hand) + " is offline"};
  if (hand::needs_initialization(valid.command) && !facts.initialized) {
    return Rejection{msg::NOT_INITIALIZED,
                     who(hand) + " is not initialized; " + command_name(command) + " needs it"};
  }
  if (valid.needs_lease && facts.lease_blocker) {
    return Rejection{msg::DENIED,
                     lease_refusal(who(hand), *facts.lease_blocker,
                                   "only it may send " + command_name(command),
                                   facts.client_id_names_blocker)};
  }
  return std::nullopt;
}

}  // namespace

bool allowed_in_group(msg::CommandType command) {
  switch (command) {
    case msg::INITIALIZE:
    case msg::MOVE:
    case msg::ROTATE:
    case msg::GRASP:
    case msg::RELEASE:
    case msg::SET_CLOSING_FORCE:
    case msg::SET_OPENING_FORCE:
      return true;
    default:
      return false;
  }
}

Result<std::vector<ValidRequest>, GroupRefusal> validate_group(const msg::GroupRequest& request,
                                                               const HandDirectory& directory,
                                                               const FactsOf& facts) {
  GroupRefusal refusal;
  const auto& hands = request.hands();
  if (hands.empty() || hands.size() > limits::GROUP_MAX_HANDS) {
    refusal.whole = Rejection{msg::INVALID_ARGUMENT,
                              "a group names 1 to " + std::to_string(limits::GROUP_MAX_HANDS) +
                                  " hands, not " + std::to_string(hands.size())};
    return fail(std::move(refusal));
  }
  if (!allowed_in_group(request.command())) {
    refusal.whole = Rejection{msg::INVALID_ARGUMENT,
                              command_name(request.command()) +
                                  " is not a group command (INITIALIZE, MOVE, ROTATE, GRASP, "
                                  "RELEASE, SET_CLOSING_FORCE, SET_OPENING_FORCE)"};
    return fail(std::move(refusal));
  }
  std::vector<ValidRequest> valid;
  std::set<std::pair<std::uint16_t, std::uint8_t>> seen;
  for (std::size_t i = 0; i < hands.size(); ++i) {
    msg::HandAddress hand = hands[i];
    if (hand.service().empty()) hand.service(request.service());
    auto member = validate_request(member_request(request, hand), directory, false);
    if (!member) {
      refusal.members.push_back(MemberRefusal{i, std::move(member).error()});
      continue;
    }
    if (!seen.insert({member->bus, member->can_id}).second) {
      refusal.members.push_back(
          MemberRefusal{i, Rejection{msg::INVALID_ARGUMENT, who(hand) + " is named twice"}});
      continue;
    }
    if (auto why = check_facts(*member, hand, facts(member->bus, member->can_id),
                               request.command())) {
      refusal.members.push_back(MemberRefusal{i, std::move(*why)});
      continue;
    }
    valid.push_back(std::move(*member));
  }
  if (!refusal.members.empty()) return fail(std::move(refusal));
  return valid;
}

}  // namespace dh3::dds
