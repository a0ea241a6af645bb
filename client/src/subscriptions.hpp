#pragma once
// The user's event and status callbacks, and the one dispatcher thread that
// runs them, and the completion callbacks of calls, in the order posted.
//
// Thread-safe, with its own mutex, taken after ClientCore's state mutex (posts
// come under it, so they keep the cache's order) and never calling out under it.

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "dh3/client.hpp"
#include "dh3/types.hpp"
#include "dispatcher.hpp"

namespace dh3::detail {

class ClientCore;

/// One subscription, shared by its dh3::Subscription handle and the posted callbacks.
struct SubscriptionState {
  std::mutex run_mutex;  ///< held while the callback runs
  std::atomic<bool> active{true};
  EventCallback on_event;
  StatusCallback on_status;
  std::optional<HandAddress> only;
  std::weak_ptr<ClientCore> core;
};

class Subscriptions {
 public:
  /// Posts `status` to the status subscriptions of its hand.
  void post_status(const HandStatus& status);
  /// Posts `event` to the event subscriptions of its hand.
  void post_event(const HandEvent& event);
  /// Posts a call's completion callback; it runs even if stop() comes first
  /// (at once, on this thread, once stopped).
  void post_completion(std::function<void()> callback);

  /// Adds an event subscription (`state->on_event` set).
  void add_events(const std::shared_ptr<SubscriptionState>& state);
  /// Adds a status subscription (`state->on_status` set); `known`, the
  /// statuses cached now, are posted to it first, so it sees every hand's
  /// statuses in order when the caller holds the lock its posts come under.
  void add_status(const std::shared_ptr<SubscriptionState>& state, std::vector<HandStatus> known);
  /// Ends a subscription and waits for its callback in progress, unless
  /// called from a callback.
  void remove(const std::shared_ptr<SubscriptionState>& state);

  [[nodiscard]] bool on_dispatcher_thread() const { return dispatcher_.on_dispatcher_thread(); }
  /// Drops the event and status callbacks queued, runs the completions
  /// queued, and ends the dispatcher thread.
  void stop() { dispatcher_.stop(); }

 private:
  /// Posts `deliver` for each of `subs` that takes samples about `about`
  /// (it follows that hand, or every hand); mutex_ held.
  template <typename Deliver>
  void post_to(const std::vector<std::shared_ptr<SubscriptionState>>& subs,
               const HandAddress& about, Deliver deliver);

  std::mutex mutex_;  ///< guards the two lists
  std::vector<std::shared_ptr<SubscriptionState>> event_subs_;
  std::vector<std::shared_ptr<SubscriptionState>> status_subs_;
  Dispatcher dispatcher_;
};

}  // namespace dh3::detail
