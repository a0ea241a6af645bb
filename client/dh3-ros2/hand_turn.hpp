#pragma once
// Whose turn it is to drive one hand, shared by every action and service
// dh3-ros2 serves for it: one at a time holds the hand (and dh3-ros2's lease
// on it). A goal preempts the goal holding the hand (it is told to cancel and
// the new one waits for it); a service does not wait but refuses while a goal
// holds the hand, so a service's lease release cannot end a goal's lease.

#include <atomic>
#include <memory>
#include <mutex>

namespace dh3::ros2 {

class HandTurn {
 public:
  /// A goal's cancel flag, set by a cancel, a newer goal or the end of dh3-ros2.
  using Cancel = std::shared_ptr<std::atomic<bool>>;

  /// Cancels the goal holding the hand, waits until the hand is free, then
  /// holds it for the goal `cancel` belongs to, until the lock goes.
  [[nodiscard]] std::unique_lock<std::mutex> take_for_goal(const Cancel& cancel);
  /// The hand for a service, or a lock that owns nothing while it is held.
  [[nodiscard]] std::unique_lock<std::mutex> try_take();

 private:
  std::mutex driving_;  // held by whoever drives the hand
  std::mutex mutex_;    // running_
  Cancel running_;
};

}  // namespace dh3::ros2
