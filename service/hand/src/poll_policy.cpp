#include "dh3/hand/poll_policy.hpp"

#include <algorithm>

namespace dh3::hand {
namespace {

enum Index : std::size_t { position, grip_status, rotation, rotation_status, initialize };

std::optional<TimePoint> due_at(const PollPlan& plan, const PollTimes& last_read, std::size_t i) {
  if (!plan.period[i]) return std::nullopt;
  if (!last_read[i]) return TimePoint::min();
  return *last_read[i] + *plan.period[i];
}

std::optional<Duration> fastest_period(const PollPlan& plan) {
  std::optional<Duration> fastest;
  for (const auto& period : plan.period) {
    if (period && (!fastest || *period < *fastest)) fastest = period;
  }
  return fastest;
}

}  // namespace

PollPlan plan_polls(const PollActivity& activity, const PollIntervals& intervals) {
  PollPlan plan;
  // A hand at rest: everything now and then, its initialization flag included,
  // so that a hand that rebooted (and lost its initialization) is noticed.
  plan.period.fill(intervals.idle);
  if (activity.initializing) {
    // Calibrating: read as while moving; the flag has its own check.
    plan.period[initialize].reset();
    for (Index i : {position, grip_status, rotation, rotation_status}) {
      plan.period[i] = std::min(*plan.period[i], intervals.moving);
    }
  }
  const bool fingers_watched = activity.fingers != FingerActivity::idle;
  if (activity.initializing || (!fingers_watched && !activity.rotating)) return plan;
  // A watched status is read in every frame the hand may get: any other read
  // would take the slot a catch, slip or arrival is heard in, and a change
  // would wait a whole interval more. The position (rotation) is read once
  // the motion ended (the driver's confirming read), the idle round when the
  // hand is at rest again; a hand that rebooted while holding shows as a drop.
  plan.period.fill(std::nullopt);
  if (fingers_watched) plan.period[grip_status] = std::min(intervals.watch, intervals.idle);
  if (activity.rotating) plan.period[rotation_status] = std::min(intervals.watch, intervals.idle);
  // Where a motion is, now and then, for whoever watches it move; the watched
  // status keeps every other frame (next_poll puts it first after a slower read).
  if (intervals.during_motion > Duration::zero()) {
    const bool fingers_move = activity.fingers == FingerActivity::closing ||
                              activity.fingers == FingerActivity::opening;
    if (fingers_move) plan.period[position] = intervals.during_motion;
    if (activity.rotating) plan.period[rotation] = intervals.during_motion;
  }
  return plan;
}

std::optional<std::size_t> next_poll(const PollPlan& plan, const PollTimes& last_read,
                                     std::optional<std::size_t> previous, TimePoint now) {
  const std::optional<Duration> fastest = fastest_period(plan);
  if (!fastest) return std::nullopt;
  const bool previous_was_slow =
      previous && plan.period[*previous] && *plan.period[*previous] > *fastest;
  std::optional<std::size_t> best;
  std::optional<TimePoint> best_due;
  for (std::size_t i = 0; i < kPolledCount; ++i) {
    const std::optional<TimePoint> due = due_at(plan, last_read, i);
    if (!due || *due > now) continue;
    if (previous_was_slow && *plan.period[i] > *fastest) continue;
    if (!best_due || *due < *best_due) {
      best = i;
      best_due = due;
    }
  }
  if (best || !previous_was_slow) return best;
  // No fast register is due: the slow ones need not wait.
  return next_poll(plan, last_read, std::nullopt, now);
}

std::optional<TimePoint> next_poll_due(const PollPlan& plan, const PollTimes& last_read) {
  std::optional<TimePoint> earliest;
  for (std::size_t i = 0; i < kPolledCount; ++i) {
    const std::optional<TimePoint> due = due_at(plan, last_read, i);
    if (due && (!earliest || *due < *earliest)) earliest = due;
  }
  return earliest;
}

}  // namespace dh3::hand
