// Subscriptions: user callbacks for events and statuses, run on the
// dispatcher thread in the order the samples arrived.

#include "subscriptions.hpp"

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

void Subscriptions::post_status(const HandStatus& status) {
  std::lock_guard lock(mutex_);
  post_to(status_subs_, status.address,
          [status](const SubscriptionState& sub) { sub.on_status(status); });
}

void Subscriptions::post_event(const HandEvent& event) {
  std::lock_guard lock(mutex_);
  post_to(event_subs_, event.hand, [event](const SubscriptionState& sub) { sub.on_event(event); });
}

template <typename Deliver>
void Subscriptions::post_to(const std::vector<std::shared_ptr<SubscriptionState>>& subs,
                            const HandAddress& about, Deliver deliver) {
  std::vector<std::shared_ptr<SubscriptionState>> targets;
  for (const auto& sub : subs) {
    if (!sub->only || *sub->only == about) targets.push_back(sub);
  }
  if (targets.empty()) return;
  // Posted under the lock: two posts keep their order on the dispatcher.
  dispatcher_.post([targets = std::move(targets), deliver = std::move(deliver)] {
    for (const auto& sub : targets) {
      std::lock_guard run(sub->run_mutex);
      if (sub->active) run_guarded([&] { deliver(*sub); });
    }
  });
}

void Subscriptions::post_completion(std::function<void()> callback) {
  dispatcher_.post_must_run([callback = std::move(callback)] { run_guarded(callback); });
}

void Subscriptions::add_events(const std::shared_ptr<SubscriptionState>& state) {
  std::lock_guard lock(mutex_);
  event_subs_.push_back(state);
}

void Subscriptions::add_status(const std::shared_ptr<SubscriptionState>& state,
                               std::vector<HandStatus> known) {
  std::lock_guard lock(mutex_);
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
}

void Subscriptions::remove(const std::shared_ptr<SubscriptionState>& state) {
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
