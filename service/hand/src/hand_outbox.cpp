#include "hand_outbox.hpp"

#include <utility>

namespace dh3::hand {

HandOutbox::HandOutbox(HandObserver& observer, HandRoster& roster, BusLatencyCounters& latency,
                       Duration fresh_interval, bool anonymous)
    : observer_(observer),
      roster_(roster),
      latency_(latency),
      fresh_interval_(fresh_interval),
      anonymous_(anonymous) {}

void HandOutbox::add_event(HandEvent event) {
  events_.push_back(std::move(event));
}

void HandOutbox::add_completion(Completion done, CommandResult result, TimePoint submitted) {
  completions_.push_back({std::move(done), std::move(result), submitted});
}

bool HandOutbox::report_state(HandState& state, TimePoint now) {
  if (anonymous_) return false;
  if (!ever_published_ || roster_.differs_from_published(state)) {
    ever_published_ = true;
    ++state.sequence;
    state.updated_at = now;
    published_read_at_ = state.read_at;
    roster_.publish(state);
    observer_.on_state(state);
    return true;
  }
  if (state.read_at >= published_read_at_ + fresh_interval_) {
    published_read_at_ = state.read_at;
    roster_.publish(state);  // the same fields, read again
    observer_.on_fresh(state);
    return true;
  }
  return false;
}

void HandOutbox::deliver(HandState& state, TimePoint now) {
  const bool reported = report_state(state, now);
  // The observer writes the sample out before this returns (on_batch_end).
  if (reported && state.read_at != TimePoint{}) latency_.sample_age.observe(now - state.read_at);
  // Callbacks may call back into the scheduler (submit): take the lists first.
  auto events = std::exchange(events_, {});
  for (const HandEvent& event : events) observer_.on_event(event);
  auto completions = std::exchange(completions_, {});
  for (auto& [done, result, submitted] : completions) {
    latency_.command_to_reply.observe(now - submitted);
    if (done) done(result);
  }
  if (reported) observer_.on_batch_end(state.can_id);
}

}  // namespace dh3::hand
