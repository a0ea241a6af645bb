#pragma once
// Several hands' commands that leave together (a group command). Each member
// command carries the same GroupRelease. A member's driver holds the frame
// that starts its motion (the position or rotation write, the initialize
// write, a force write) until every member has such a frame ready and its own
// command interval clear; the last to get there fixes one release instant for
// all, and each scheduler sends its members' frames at that instant, back to
// back, before any other frame of that pass. The steps before that frame (a
// grasp's force write, initialize's feedback enable, the read of the
// initialization flag) go as they come.
//
// If any member's command ends before the release (refused, cancelled, timed
// out, offline), the group is abandoned: the members still holding end
// CANCELLED and no held frame is sent. After the release nothing is taken
// back: each member's command ends on its own, as a single command would.
//
// Thread-safe: members on several buses report from their buses' loops.

#include <cstddef>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "dh3/base/clock.hpp"

namespace dh3::hand {

class GroupRelease {
 public:
  /// `members`: how many commands share it. `lead`: how far after the last
  /// member got ready the release lies, so that the other buses' loops, woken
  /// then, are waiting for it when it comes (zero when all are on one bus: its
  /// own next pass sends them). `deadline`: if the group is not released by
  /// then, it is abandoned.
  GroupRelease(std::size_t members, Duration lead, TimePoint deadline);

  enum class Verdict : std::uint8_t {
    hold,       ///< not every member is ready, or the release instant is ahead
    go,         ///< send the held frame now
    abandoned,  ///< a member failed before the release: end CANCELLED
  };

  /// A member's frame is ready and its interval clear at `now`. `wake` makes
  /// that member's loop run a pass (called, on any thread, when the release
  /// instant is fixed or the group abandoned). Once per member.
  void ready(TimePoint now, std::function<void()> wake);
  /// What a ready member does at `now`.
  [[nodiscard]] Verdict verdict(TimePoint now);
  /// A member's command ended before its frame left: the group is abandoned,
  /// unless it was released already. `why` is kept for the other members.
  void abandon(const std::string& why);
  /// The release instant, once every member is ready.
  [[nodiscard]] std::optional<TimePoint> release_at() const;
  [[nodiscard]] std::string abandoned_because() const;

 private:
  void wake_all_locked();

  mutable std::mutex mutex_;
  const std::size_t members_;
  const Duration lead_;
  const TimePoint deadline_;
  std::size_t ready_ = 0;
  std::optional<TimePoint> release_at_;
  bool abandoned_ = false;
  std::string why_;
  std::vector<std::function<void()>> wakes_;
};

}  // namespace dh3::hand
