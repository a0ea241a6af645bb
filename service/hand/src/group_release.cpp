#include "dh3/hand/group_release.hpp"

#include <algorithm>

namespace dh3::hand {

GroupRelease::GroupRelease(std::size_t members, Duration lead, TimePoint deadline)
    : members_(members), lead_(lead), deadline_(deadline) {}

void GroupRelease::ready(TimePoint now, std::function<void()> wake) {
  std::lock_guard lock(mutex_);
  if (wake) wakes_.push_back(std::move(wake));
  if (abandoned_ || release_at_) return;
  if (++ready_ < members_) return;
  // Every member was clear when it reported, and none has sent since: the
  // last one's time (plus the lead) is clear for all.
  release_at_ = now + lead_;
  wake_all_locked();
}

GroupRelease::Verdict GroupRelease::verdict(TimePoint now) {
  std::lock_guard lock(mutex_);
  if (abandoned_) return Verdict::abandoned;
  if (release_at_) return now >= *release_at_ ? Verdict::go : Verdict::hold;
  if (now >= deadline_) {
    abandoned_ = true;
    why_ = "not every hand of the group was ready in time";
    wake_all_locked();
    return Verdict::abandoned;
  }
  return Verdict::hold;
}

void GroupRelease::abandon(const std::string& why) {
  std::lock_guard lock(mutex_);
  if (abandoned_ || release_at_) return;
  abandoned_ = true;
  why_ = why;
  wake_all_locked();
}

std::optional<TimePoint> GroupRelease::release_at() const {
  std::lock_guard lock(mutex_);
  return release_at_;
}

std::string GroupRelease::abandoned_because() const {
  std::lock_guard lock(mutex_);
  return why_;
}

void GroupRelease::wake_all_locked() {
  // Bus::wake() only writes to an eventfd: safe under the lock.
  for (const auto& wake : wakes_) wake();
}

}  // namespace dh3::hand
