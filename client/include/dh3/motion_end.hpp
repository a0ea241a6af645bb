#pragma once
// The event that ends a motion a command started: fed every event of one hand
// (Hand::subscribe(), on the client's dispatcher thread) and waited on from
// the thread that sent the command.
//
//   dh3::MotionEnd::Rule rule;
//   rule.target = 60;
//   dh3::MotionEnd end(rule);
//   auto watching = hand.subscribe([&end](const dh3::HandEvent& e) { end.offer(e); });
//   if (hand.move_to(60).ok()) {
//     const auto ended = end.wait(std::chrono::steady_clock::now() + std::chrono::seconds(10));
//   }
//
// Subscribe before the command goes out, so that an end that comes fast is
// not missed.

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>

#include "dh3/export.hpp"
#include "dh3/types.hpp"

namespace dh3 {

class DH3_CLIENT_API MotionEnd {
 public:
  /// Which events end the motion. The hand going offline always does.
  struct Rule {
    /// The rotation's end events (rotation_arrived, rotation_blocked) rather
    /// than the fingers' (arrived, grasped, missed).
    bool rotation = false;
    /// Only an end event with this target: a stop keeps the commanded target
    /// in the event it ends the motion with, so an end of an earlier motion
    /// is told apart. Empty: any target.
    std::optional<std::int32_t> target;
    /// A drop or a fault ends it too.
    bool faults_end = false;
  };

  explicit MotionEnd(Rule rule);
  ~MotionEnd();
  MotionEnd(const MotionEnd&) = delete;
  MotionEnd& operator=(const MotionEnd&) = delete;

  /// One event of the hand; the first that ends the motion is kept. Any thread.
  void offer(const HandEvent& event);
  /// The ending event, or nothing if `deadline` passed or `stop()` returned
  /// true first (asked at least every tenth of a second, e.g. for Ctrl-C).
  [[nodiscard]] std::optional<HandEvent> wait(std::chrono::steady_clock::time_point deadline,
                                              const std::function<bool()>& stop = {});

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace dh3
