// Subscriptions: user callbacks for events and statuses, run on the
// dispatcher thread in the order the samples arrived.

#include "client_core.hpp"
#include "conversions.hpp"

namespace dh3::detail {

namespace {

/// Runs a user callback; an exception from user code must not end the
/// dispatcher thread (and with it every later callback).
template <typename F>
void run_guarded(F&& f) {
  try {
    f();
  } catch (...) {  // NOLINT(bugprone-empty-catch): the user's exception, nothing to do with it
  }
}

}  // namespace

void ClientCore::on_event(const std::string& prefix, const msg::HandEvent& sample) {
  events_taken_.fetch_add(1, std::memory_order_relaxed);
  if (!followed(sample.hand().service(), sample.hand().bus())) return;
  std::lock_guard lock(mutex_);
  if (closed_ || prefix_is_dead_locked(prefix)) return;
  post_event_locked(to_public(sample));
}

void ClientCore::post_status_locked(const HandStatus& status) {
  std::vector<std::shared_ptr<SubscriptionState>> targets;
  for (const auto& sub : status_subs_) {
    if (!sub->only || *sub->only == status.address) targets.push_back(sub);
  }
  if (targets.empty()) return;
  dispatcher_.post([targets = std::move(targets), status] {
    for (const auto& sub : targets) {
      std::lock_guard run(sub->run_mutex);
      if (sub->active) run_guarded([&] { sub->on_status(status); });
    }
  });
}

void ClientCore::post_event_locked(const HandEvent& event) {
  std::vector<std::shared_ptr<SubscriptionState>> targets;
  for (const auto& sub : event_subs_) {
    if (!sub->only || *sub->only == event.hand) targets.push_back(sub);
  }
  if (targets.empty()) return;
  dispatcher_.post([targets = std::move(targets), event] {
    for (const auto& sub : targets) {
      std::lock_guard run(sub->run_mutex);
      if (sub->active) run_guarded([&] { sub->on_event(event); });
    }
  });
}

std::shared_ptr<SubscriptionState> ClientCore::subscribe_events(EventCallback callback,
                                                                std::optional<HandAddress> only) {
  auto state = std::make_shared<SubscriptionState>();
  state->on_event = std::move(callback);
  state->only = std::move(only);
  state->core = weak_from_this();
  std::lock_guard lock(mutex_);
  if (closed_) {
    state->active = false;
  } else {
    event_subs_.push_back(state);
  }
  return state;
}

std::shared_ptr<SubscriptionState> ClientCore::subscribe_status(StatusCallback callback,
                                                                std::optional<HandAddress> only) {
  auto state = std::make_shared<SubscriptionState>();
  state->on_status = std::move(callback);
  state->only = std::move(only);
  state->core = weak_from_this();
  std::lock_guard lock(mutex_);
  if (closed_) {
    state->active = false;
    return state;
  }
  // The statuses known now go first, posted under the same lock as later
  // samples, so the subscriber sees every hand's statuses in order.
  std::vector<HandStatus> known;
  for (const auto& [address, status] : statuses_) {
    if (!state->only || *state->only == address) known.push_back(status);
  }
  if (!known.empty()) {
    dispatcher_.post([state, known = std::move(known)] {
      std::lock_guard run(state->run_mutex);
      for (const auto& status : known) {
        if (!state->active) break;
        run_guarded([&] { state->on_status(status); });
      }
    });
  }
  status_subs_.push_back(state);
  return state;
}

void ClientCore::unsubscribe(const std::shared_ptr<SubscriptionState>& state) {
  state->active = false;
  {
    std::lock_guard lock(mutex_);
    std::erase(event_subs_, state);
    std::erase(status_subs_, state);
  }
  // Wait for a callback in progress on the dispatcher, unless we are it (an
  // unsubscribe from inside a callback).
  if (!dispatcher_.on_dispatcher_thread()) {
    std::lock_guard wait(state->run_mutex);
  }
}

}  // namespace dh3::detail
