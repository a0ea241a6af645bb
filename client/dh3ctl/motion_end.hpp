#pragma once
// dh3ctl move/rotate --wait: the event that ends the motion a command started.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>

#include "dh3/types.hpp"

namespace dh3::ctl {

/// Fed every event of one hand from the client's dispatcher thread; waited on
/// from dh3ctl's. A motion ends with the event of its axis whose target is the
/// one commanded (a stop keeps that target in the event it ends the motion
/// with), or with the hand going offline.
class MotionEnd {
 public:
  MotionEnd(bool rotation, std::int32_t target) : rotation_(rotation), target_(target) {}

  void offer(const HandEvent& event);
  /// The ending event, or nothing if `deadline` passed or `stop()` returned true first.
  template <class Stop>
  std::optional<HandEvent> wait(std::chrono::steady_clock::time_point deadline, Stop stop) {
    std::unique_lock lock(mutex_);
    while (!end_ && !stop() && std::chrono::steady_clock::now() < deadline) {
      // Woken by the event; the tenth of a second is for an interrupt (Ctrl-C).
      changed_.wait_for(lock, std::chrono::milliseconds(100));
    }
    return end_;
  }

 private:
  [[nodiscard]] bool ends_motion(const HandEvent& event) const;

  const bool rotation_;
  const std::int32_t target_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::optional<HandEvent> end_;
};

}  // namespace dh3::ctl
