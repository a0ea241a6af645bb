#include "dh3/sim/replay_hands.hpp"

#include <algorithm>

namespace dh3::sim {

ReplayHands::ReplayHands(const ReplayScript& script, TimePoint start) {
  for (const auto& [id, recorded] : script.hands()) {
    Hand& hand = hands_[id];
    hand.recorded = &recorded;
    begin_epoch(hand, 0, start);
  }
}

std::vector<std::uint8_t> ReplayHands::ids() const {
  std::vector<std::uint8_t> out;
  for (const auto& [id, hand] : hands_) out.push_back(id);
  return out;
}

void ReplayHands::begin_epoch(Hand& hand, std::size_t epoch, TimePoint now) {
  const ReplayEpoch& next = hand.recorded->epochs[epoch];
  if (epoch > 0) {
    // What the skipped rest of the old epoch ended with is how the hand stands.
    for (const auto& [reg, replies] : hand.recorded->epochs[hand.epoch].reads) {
      if (hand.used[reg] < replies.size()) hand.last[reg] = replies.back();
    }
  }
  hand.epoch = epoch;
  hand.used.clear();
  for (const RecordedUnasked& frame : next.unasked) {
    hand.unasked.push_back(Outgoing{now + frame.offset, frame.message});
  }
  std::stable_sort(hand.unasked.begin(), hand.unasked.end(),
                   [](const Outgoing& a, const Outgoing& b) { return a.due < b.due; });
}

std::optional<RecordedReply> ReplayHands::first_reply(const RecordedHand& hand,
                                                      std::uint16_t reg) {
  for (const ReplayEpoch& epoch : hand.epochs) {
    if (const auto found = epoch.reads.find(reg); found != epoch.reads.end()) {
      return found->second.front();
    }
  }
  return std::nullopt;
}

std::optional<RecordedReply> ReplayHands::read_reply(Hand& hand, std::uint16_t reg) {
  const ReplyQueues& reads = hand.recorded->epochs[hand.epoch].reads;
  if (const auto queue = reads.find(reg); queue != reads.end()) {
    std::size_t& used = hand.used[reg];
    if (used < queue->second.size()) {
      hand.last[reg] = queue->second[used++];
      return hand.last[reg];
    }
  }
  if (const auto last = hand.last.find(reg); last != hand.last.end()) return last->second;
  return first_reply(*hand.recorded, reg);
}

std::size_t ReplayHands::deliver(const protocol::Message& request, TimePoint now,
                                 std::vector<Outgoing>& replies,
                                 std::vector<Outgoing>& unsolicited) {
  const auto found = hands_.find(request.hand_id);
  if (found == hands_.end()) return 0;
  Hand& hand = found->second;
  take_due(hand, now, unsolicited);
  const std::uint16_t reg = request.reg.code();
  std::optional<RecordedReply> reply;
  if (request.access == protocol::Access::write) {
    if (hand.epoch + 1 < hand.recorded->epochs.size()) begin_epoch(hand, hand.epoch + 1, now);
    const auto queue = hand.recorded->writes.find(reg);
    std::size_t& used = hand.writes_used[reg];
    if (queue != hand.recorded->writes.end() && used < queue->second.size()) {
      reply = queue->second[used++];
    } else {
      reply = RecordedReply{request, Duration::zero()};  // a hand acknowledges every write
    }
  } else {
    reply = read_reply(hand, reg);
  }
  if (reply) replies.push_back(Outgoing{now + reply->latency, reply->message});
  return 1;
}

void ReplayHands::take_due(Hand& hand, TimePoint now, std::vector<Outgoing>& out) {
  const auto due_end = std::find_if(hand.unasked.begin(), hand.unasked.end(),
                                    [now](const Outgoing& frame) { return frame.due > now; });
  out.insert(out.end(), hand.unasked.begin(), due_end);
  hand.unasked.erase(hand.unasked.begin(), due_end);
}

void ReplayHands::advance_all(TimePoint now, std::vector<Outgoing>& out) {
  for (auto& [id, hand] : hands_) take_due(hand, now, out);
}

std::optional<TimePoint> ReplayHands::next_unsolicited_at() const {
  std::optional<TimePoint> earliest;
  for (const auto& [id, hand] : hands_) {
    if (!hand.unasked.empty() && (!earliest || hand.unasked.front().due < *earliest)) {
      earliest = hand.unasked.front().due;
    }
  }
  return earliest;
}

}  // namespace dh3::sim
