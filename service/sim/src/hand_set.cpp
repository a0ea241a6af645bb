#include "dh3/sim/hand_set.hpp"

#include <utility>

namespace dh3::sim {

bool HandSet::add(const SimHandOptions& options, TimePoint now) {
  std::unique_ptr<SimHand>& slot = hands_[options.id];
  const bool replaced = slot != nullptr;
  slot = std::make_unique<SimHand>(options, now);
  if (!replaced) ++count_;
  return replaced;
}

bool HandSet::remove(std::uint8_t id) {
  if (!hands_[id]) return false;
  hands_[id].reset();
  --count_;
  return true;
}

SimHand* HandSet::find(std::uint8_t id) {
  return hands_[id].get();
}

std::vector<std::uint8_t> HandSet::ids() const {
  std::vector<std::uint8_t> result;
  result.reserve(count_);
  for (std::size_t id = 0; id < hands_.size(); ++id) {
    if (hands_[id]) result.push_back(static_cast<std::uint8_t>(id));
  }
  return result;
}

std::size_t HandSet::deliver(const protocol::Message& request, TimePoint now,
                             std::vector<Outgoing>& replies, std::vector<Outgoing>& unsolicited) {
  const auto handle_one = [&](SimHand& hand) {
    for (Outgoing& reply : hand.handle(request, now)) replies.push_back(reply);
    for (Outgoing& frame : hand.advance(now)) unsolicited.push_back(frame);
  };
  if (request.hand_id != 0) {
    SimHand* hand = find(request.hand_id);
    if (hand == nullptr) return 0;
    handle_one(*hand);
    return 1;
  }
  std::size_t reached = 0;
  for (const std::unique_ptr<SimHand>& hand : hands_) {
    if (!hand) continue;
    handle_one(*hand);
    ++reached;
  }
  return reached;
}

void HandSet::advance_all(TimePoint now, std::vector<Outgoing>& out) {
  for (const std::unique_ptr<SimHand>& hand : hands_) {
    if (!hand) continue;
    for (Outgoing& frame : hand->advance(now)) out.push_back(frame);
  }
}

std::optional<TimePoint> HandSet::next_unsolicited_at() const {
  std::optional<TimePoint> earliest;
  for (const std::unique_ptr<SimHand>& hand : hands_) {
    if (!hand) continue;
    const std::optional<TimePoint> at = hand->next_unsolicited_at();
    if (at && (!earliest || *at < *earliest)) earliest = at;
  }
  return earliest;
}

bool HandSet::with_hand(std::uint8_t id, const std::function<void(SimHand&)>& action,
                        std::uint8_t* new_id) {
  if (!hands_[id]) return false;
  action(*hands_[id]);
  const std::uint8_t now_id = hands_[id]->id();
  if (now_id != id) {
    if (!hands_[now_id]) ++count_;
    hands_[now_id] = std::move(hands_[id]);
    --count_;
  }
  if (new_id != nullptr) *new_id = now_id;
  return true;
}

}  // namespace dh3::sim
