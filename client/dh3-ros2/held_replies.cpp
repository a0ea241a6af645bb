#include "held_replies.hpp"

#include <algorithm>
#include <utility>

namespace dh3::ros2 {

HeldReplies::HeldReplies(Clock::duration hold_limit, std::size_t cap)
    : hold_limit_(hold_limit), cap_(std::max<std::size_t>(cap, 1)) {}

bool HeldReplies::admit(const std::string& reader, Write write, Clock::time_point now) {
  std::lock_guard lock(mutex_);
  expire_locked(now);
  if (matched_.count(reader) != 0) return true;
  if (held_.size() >= cap_) {
    held_.pop_front();
    ++dropped_;
  }
  held_.push_back(Held{reader, now + hold_limit_, std::move(write)});
  return false;
}

std::vector<HeldReplies::Write> HeldReplies::reader_matched(const std::string& reader,
                                                            bool matched,
                                                            Clock::time_point now) {
  std::vector<Write> due;
  std::lock_guard lock(mutex_);
  expire_locked(now);
  if (!matched) {
    matched_.erase(reader);
    return due;
  }
  matched_.insert(reader);
  const auto first = std::stable_partition(held_.begin(), held_.end(),
                                           [&](const Held& h) { return h.reader != reader; });
  for (auto it = first; it != held_.end(); ++it) due.push_back(std::move(it->write));
  held_.erase(first, held_.end());
  return due;
}

std::size_t HeldReplies::held() const {
  std::lock_guard lock(mutex_);
  return held_.size();
}

std::size_t HeldReplies::dropped() const {
  std::lock_guard lock(mutex_);
  return dropped_;
}

void HeldReplies::expire_locked(Clock::time_point now) {
  const auto before = held_.size();
  held_.erase(std::remove_if(held_.begin(), held_.end(),
                             [&](const Held& h) { return h.until <= now; }),
              held_.end());
  dropped_ += before - held_.size();
}

}  // namespace dh3::ros2
