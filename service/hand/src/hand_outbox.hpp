#pragma once
// Loop thread only: a driver fills it during a pass and delivers it at the end;
// what it calls (observer, completions) may submit() but never reach the driver.
//
// What one hand's pass tells the world, held until the pass ends and then
// delivered in the order HandObserver promises: the hand's state (when it
// changed, or the same values read again at most once per fresh interval),
// then its events, then the completions of its commands, then on_batch_end.
// Whoever hears of an event or a result thus finds the state behind it. It
// also keeps the bus's sample-age and command-to-reply latencies, which are
// measured at delivery.

#include <vector>

#include "dh3/base/clock.hpp"
#include "dh3/hand/bus_scheduler.hpp"
#include "dh3/hand/hand_roster.hpp"
#include "dh3/hand/hand_types.hpp"
#include "hand_counters.hpp"

namespace dh3::hand {

class HandOutbox {
 public:
  /// `fresh_interval`: how often an unchanged state read again is reported
  /// (SchedulerOptions::poll_interval_idle). `anonymous`: ID 0, which
  /// publishes no state (its completions are still delivered).
  HandOutbox(HandObserver& observer, HandRoster& roster, BusLatencyCounters& latency,
             Duration fresh_interval, bool anonymous);

  void add_event(HandEvent event);
  /// A command ended; `submitted`: when it was submitted, for its latency.
  void add_completion(Completion done, CommandResult result, TimePoint submitted);
  /// The next delivery publishes the state even if the roster has it already.
  void publish_again() { ever_published_ = false; }

  /// Publishes `state` if it changed (setting its sequence and updated_at) or
  /// is due as fresh, then hands out the events and completions held.
  void deliver(HandState& state, TimePoint now);

 private:
  struct PendingCompletion {
    Completion done;
    CommandResult result;
    TimePoint submitted{};
  };
  /// Publishes the state if due; true if it was (the batch then ends with on_batch_end).
  bool report_state(HandState& state, TimePoint now);

  HandObserver& observer_;
  HandRoster& roster_;
  BusLatencyCounters& latency_;
  Duration fresh_interval_;
  bool anonymous_;
  bool ever_published_ = false;
  /// read_at of the last state told to the observer (on_state or on_fresh).
  TimePoint published_read_at_{};
  std::vector<HandEvent> events_;
  std::vector<PendingCompletion> completions_;
};

}  // namespace dh3::hand
