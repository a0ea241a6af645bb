#pragma once
// Loop thread only: its driver asks and tells it, and tells it the time. The
// one thing shared: the hand's atomic `queued` count, raised by submit() on any thread.
//
// The commands of one hand that have not ended: those waiting for their turn
// (the queue), the one being sent (the active job, ActiveJob), and those whose
// frames are done and that wait for the hand to get somewhere (InitWaiter,
// MotionWaiter). Every command leaves it with one result, counted and queued
// in the outbox; a group member that fails abandons its group first, so that
// no member moves alone. The completions wait in the driver's outbox until
// the pass ends. It lowers `queued` as commands leave the queue.

#include <atomic>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>

#include "dh3/base/clock.hpp"
#include "dh3/hand/hand_types.hpp"
#include "hand_counters.hpp"
#include "hand_driver_states.hpp"
#include "hand_outbox.hpp"

namespace dh3::hand {

class CommandLedger {
 public:
  /// `label`: the hand as its group's abandon reason names it ("bus/3 (left)").
  CommandLedger(std::atomic<int>& queued, HandCounters& counters, HandOutbox& outbox,
                std::string label);

  /// Queues a command (validated and counted in `queued`). A stop goes first and
  /// cancels every motion not yet under way; a motion supersedes the queued
  /// ones of its axes (the hand would do the same: "position command can be
  /// interrupted").
  void add(DriverJob job);
  /// Cancels the queued motions of the axes named, the active one if its
  /// motion frame has not gone, and (fingers) the grasp or release waiting.
  void cancel_motion(bool fingers, bool rotation);

  /// The next queued command, out of the queue; those whose own timeout has
  /// passed at `now` end on the way with TIMEOUT.
  [[nodiscard]] std::optional<DriverJob> take_next(TimePoint now);
  /// Makes `job` the one being sent (there is none).
  void start(ActiveJob job) { active_ = std::move(job); }
  [[nodiscard]] ActiveJob* active() { return active_ ? &*active_ : nullptr; }
  [[nodiscard]] const ActiveJob* active() const { return active_ ? &*active_ : nullptr; }
  /// A command is being sent or waits for its turn.
  [[nodiscard]] bool has_commands() const { return active_ || !queue_.empty(); }

  /// The active initialize was echoed: it waits for the hand to finish until
  /// `deadline` (an earlier one waiting is cancelled).
  void active_waits_for_init(TimePoint deadline);
  /// The active grasp or release was echoed: it waits for finger motion
  /// `epoch` to end until `deadline` (an earlier one waiting is cancelled).
  void active_waits_for_motion(TimePoint deadline, std::uint64_t epoch);
  [[nodiscard]] const InitWaiter* init_waiter() const {
    return init_waiter_ ? &*init_waiter_ : nullptr;
  }
  [[nodiscard]] MotionWaiter* motion_waiter() {
    return motion_waiter_ ? &*motion_waiter_ : nullptr;
  }
  [[nodiscard]] const MotionWaiter* motion_waiter() const {
    return motion_waiter_ ? &*motion_waiter_ : nullptr;
  }

  void finish_active(const CommandResult& result);
  void finish_init_waiter(const CommandResult& result);
  void finish_motion_waiter(const CommandResult& result);
  /// Ends every command it holds with `error` (link lost, shutdown).
  void fail_everything(CommandError error);
  /// Ends `job`, which it no longer holds: counted, its completion queued.
  void complete(DriverJob& job, const CommandResult& result);

  /// Ends the queued commands whose own timeout has passed at `now`.
  void expire_queued(TimePoint now);
  /// The earliest deadline of a waiter or a queued command's own timeout.
  [[nodiscard]] std::optional<TimePoint> next_deadline() const;

 private:
  std::atomic<int>& queued_;
  HandCounters& counters_;
  HandOutbox& outbox_;
  std::string label_;
  std::deque<DriverJob> queue_;
  std::optional<ActiveJob> active_;
  std::optional<InitWaiter> init_waiter_;
  std::optional<MotionWaiter> motion_waiter_;
};

}  // namespace dh3::hand
