#include "dh3/motion_end.hpp"

#include <algorithm>
#include <condition_variable>
#include <mutex>

namespace dh3 {

namespace {

/// How often a wait asks its stop function.
constexpr std::chrono::milliseconds kStopCheck{100};

bool ends_motion(const MotionEnd::Rule& rule, const HandEvent& event) {
  switch (event.kind) {
    case EventKind::offline:
      return true;
    case EventKind::arrived:
    case EventKind::grasped:
    case EventKind::missed:
      return !rule.rotation && (!rule.target || event.target == *rule.target);
    case EventKind::rotation_arrived:
    case EventKind::rotation_blocked:
      return rule.rotation && (!rule.target || event.target == *rule.target);
    case EventKind::dropped:
    case EventKind::fault:
      return rule.faults_end;
    default:
      return false;
  }
}

}  // namespace

struct MotionEnd::State {
  explicit State(Rule ending) : rule(std::move(ending)) {}
  const Rule rule;
  std::mutex mutex;
  std::condition_variable changed;
  std::optional<HandEvent> end;  ///< under mutex
};

MotionEnd::MotionEnd(Rule rule) : state_(std::make_unique<State>(std::move(rule))) {}
MotionEnd::~MotionEnd() = default;

void MotionEnd::offer(const HandEvent& event) {
  if (!ends_motion(state_->rule, event)) return;
  std::lock_guard lock(state_->mutex);
  if (!state_->end) state_->end = event;
  state_->changed.notify_all();
}

std::optional<HandEvent> MotionEnd::wait(std::chrono::steady_clock::time_point deadline,
                                         const std::function<bool()>& stop) {
  std::unique_lock lock(state_->mutex);
  while (!state_->end && !(stop && stop())) {
    const auto now = std::chrono::steady_clock::now();
    if (now >= deadline) break;
    // Woken by the event; the check is for the stop function.
    state_->changed.wait_until(lock, std::min(deadline, now + kStopCheck));
  }
  return state_->end;
}

}  // namespace dh3
