#include "reply_gate.hpp"

#include <algorithm>
#include <iterator>

namespace dh3::dds {

template <typename Reply>
void ReplyGate<Reply>::participant_joined(const std::string& client_id) {
  std::lock_guard lock(mutex_);
  clients_.try_emplace(client_id);
}

template <typename Reply>
std::size_t ReplyGate<Reply>::participant_left(const std::string& client_id) {
  std::lock_guard lock(mutex_);
  const auto it = clients_.find(client_id);
  if (it == clients_.end()) return 0;
  const std::size_t dropped = it->second.held.size();
  held_ -= dropped;
  clients_.erase(it);
  return dropped;
}

template <typename Reply>
std::vector<Reply> ReplyGate<Reply>::reader_matched(const std::string& client_id, bool matched) {
  std::lock_guard lock(mutex_);
  // A reader may match before its participant's discovery is reported.
  Client& client = clients_[client_id];
  client.readers = std::max(0, client.readers + (matched ? 1 : -1));
  std::vector<Reply> released;
  if (client.readers == 0) return released;
  released.reserve(client.held.size());
  for (auto& held : client.held) released.push_back(std::move(held.reply));
  held_ -= client.held.size();
  client.held.clear();
  return released;
}

template <typename Reply>
Admission ReplyGate<Reply>::admit(Reply& reply) {
  std::lock_guard lock(mutex_);
  const auto it = clients_.find(reply.client_id());
  if (it == clients_.end() || it->second.readers > 0) return {};
  Admission admission{GateOutcome::held, make_room_locked(it)};
  it->second.held.push_back(Held{clock_.now(), std::move(reply)});
  ++held_;
  return admission;
}

template <typename Reply>
std::optional<DroppedReply> ReplyGate<Reply>::make_room_locked(typename Clients::iterator client) {
  auto victim = clients_.end();
  bool over_total = false;
  if (client->second.held.size() >= caps_.per_client) {
    victim = client;
  } else if (held_ >= caps_.total) {
    over_total = true;
    victim = std::max_element(clients_.begin(), clients_.end(), [](const auto& a, const auto& b) {
      return a.second.held.size() < b.second.held.size();
    });
  }
  if (victim == clients_.end() || victim->second.held.empty()) return std::nullopt;
  Client& from = victim->second;
  DroppedReply dropped{victim->first, from.held.front().reply.request_seq(), ++from.dropped,
                       over_total};
  from.held.pop_front();
  --held_;
  ++dropped_;
  return dropped;
}

template <typename Reply>
std::vector<Reply> ReplyGate<Reply>::expire() {
  std::lock_guard lock(mutex_);
  return take_locked(clock_.now() - hold_limit_);
}

template <typename Reply>
std::vector<Reply> ReplyGate<Reply>::take_all() {
  std::lock_guard lock(mutex_);
  return take_locked(TimePoint::max());
}

template <typename Reply>
std::vector<Reply> ReplyGate<Reply>::take_locked(TimePoint due) {
  std::vector<Held> taken;
  for (auto& [id, client] : clients_) {
    // Held in arrival order: those held since before `due` are a prefix.
    const auto end = std::find_if(client.held.begin(), client.held.end(),
                                  [&](const Held& held) { return held.since > due; });
    held_ -= static_cast<std::size_t>(end - client.held.begin());
    std::move(client.held.begin(), end, std::back_inserter(taken));
    client.held.erase(client.held.begin(), end);
  }
  std::stable_sort(taken.begin(), taken.end(),
                   [](const Held& a, const Held& b) { return a.since < b.since; });
  std::vector<Reply> replies;
  replies.reserve(taken.size());
  for (auto& held : taken) replies.push_back(std::move(held.reply));
  return replies;
}

template <typename Reply>
std::optional<TimePoint> ReplyGate<Reply>::next_expiry() const {
  std::lock_guard lock(mutex_);
  std::optional<TimePoint> next;
  for (const auto& [id, client] : clients_) {
    if (client.held.empty()) continue;
    const TimePoint at = client.held.front().since + hold_limit_;
    if (!next || at < *next) next = at;
  }
  return next;
}

template <typename Reply>
std::size_t ReplyGate<Reply>::held() const {
  std::lock_guard lock(mutex_);
  return held_;
}

template <typename Reply>
std::size_t ReplyGate<Reply>::dropped(const std::string& client_id) const {
  std::lock_guard lock(mutex_);
  const auto it = clients_.find(client_id);
  return it == clients_.end() ? 0 : it->second.dropped;
}

template <typename Reply>
std::size_t ReplyGate<Reply>::dropped() const {
  std::lock_guard lock(mutex_);
  return dropped_;
}

template class ReplyGate<msg::CommandReply>;
template class ReplyGate<msg::GroupReply>;

}  // namespace dh3::dds
