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
  clients_.erase(it);
  return dropped;
}

template <typename Reply>
std::vector<Reply> ReplyGate<Reply>::reader_matched(const std::string& client_id,
                                                         bool matched) {
  std::lock_guard lock(mutex_);
  // A reader may match before its participant's discovery is reported.
  Client& client = clients_[client_id];
  client.readers = std::max(0, client.readers + (matched ? 1 : -1));
  std::vector<Reply> released;
  if (client.readers == 0) return released;
  released.reserve(client.held.size());
  for (auto& held : client.held) released.push_back(std::move(held.reply));
  client.held.clear();
  return released;
}

template <typename Reply>
GateOutcome ReplyGate<Reply>::admit(Reply& reply) {
  std::lock_guard lock(mutex_);
  const auto it = clients_.find(reply.client_id());
  if (it == clients_.end() || it->second.readers > 0) return GateOutcome::pass;
  it->second.held.push_back(Held{clock_.now(), std::move(reply)});
  return GateOutcome::held;
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
  std::size_t n = 0;
  for (const auto& [id, client] : clients_) n += client.held.size();
  return n;
}

template class ReplyGate<msg::CommandReply>;
template class ReplyGate<msg::GroupReply>;

}  // namespace dh3::dds
