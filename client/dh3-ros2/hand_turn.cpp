#include "hand_turn.hpp"

namespace dh3::ros2 {

std::unique_lock<std::mutex> HandTurn::take_for_goal(const Cancel& cancel) {
  {
    std::lock_guard lock(mutex_);
    if (running_) *running_ = true;  // a new goal preempts the one running
  }
  std::unique_lock driving(driving_);
  std::lock_guard lock(mutex_);
  running_ = cancel;
  return driving;
}

std::unique_lock<std::mutex> HandTurn::try_take() {
  return std::unique_lock(driving_, std::try_to_lock);
}

}  // namespace dh3::ros2
