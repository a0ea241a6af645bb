#pragma once
// What dh3::Client and dh3::Hand share: a coordinator over the classes that
// know the services (ServiceTracker), the hands' statuses (StatusCache), the
// calls under way (PendingCalls, single and group alike), the user's callbacks
// (Subscriptions) and the DDS wiring (ClientEndpoints).
//
// Threading: one state mutex, `mutex_`, guards closed_, io_kick_, tracker_,
// cache_, calls_ and made_events_ (a service's loss changes them in one step,
// and the waits look at several); Subscriptions has its own mutex, always
// taken after it, and the Dispatcher's after that. No lock is held while a
// call's `done` runs, a request is written or a user callback runs.
//   - Fast DDS listener threads deliver samples, matches and participant
//     changes (ClientEndpoints); they update the state and never write to DDS.
//   - The calling thread writes its request itself when the service is ready
//     and no other request is queued or being written (so the requests of one
//     thread keep their order); otherwise, and for calls made on a DDS
//     listener thread (a call chained from a reply), the internal "io" thread
//     writes it. close() waits for writes in progress before it deletes the
//     DDS entities. The io thread also ends calls whose deadline passed; a call
//     wakes it only when its deadline comes before the io thread's next wake.
//   - One dispatcher thread (Subscriptions) runs user callbacks, in order:
//     events, statuses and the completion callbacks of calls (a call's `done`
//     posts them; the `done` of a std::future fulfils it where the call ends).
//     User code never runs on a DDS thread, so a callback that makes a
//     blocking call cannot hold up the very reply it waits for.
//
// A service "incarnation" is the DDS participant that serves it (its GUID
// prefix; service_tracker.hpp says which is current and when it is ready). A
// call is written only once its service is ready (a request written earlier
// would be lost: the topics are volatile), and a program that waited for a
// ready service gets every event from then on. When the incarnation leaves the
// domain, or a newer one of the same name appears (a restart), the calls
// written to the old one end SERVICE_LOST and its hands go offline; calls not
// yet written wait for the next incarnation until their deadline.
//
// Read-only clients: DDS Security may refuse an identity the request writer,
// the reply reader or the service info reader (deploy/security's "monitor"
// may only read statuses and events). Such a client stays connected: services
// are known from their participants and status samples, a service is ready
// once its event writer matched, and every command ends at once, locally,
// with DENIED.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "client_made_events.hpp"
#include "dh3/address.hpp"
#include "dh3/base/result.hpp"
#include "dh3/client.hpp"
#include "dh3/contract/dh3.h"
#include "dh3/contract/follow_filter.hpp"
#include "dh3/types.hpp"
#include "group_calls.hpp"
#include "pending_calls.hpp"
#include "service_tracker.hpp"
#include "status_cache.hpp"
#include "subscriptions.hpp"

namespace dh3::detail {

class EndpointCreator;
class ClientEndpoints;

class ClientCore : public std::enable_shared_from_this<ClientCore> {
 public:
  using Done = PendingCalls::Done;
  using GroupDone = PendingCalls::GroupDone;

  explicit ClientCore(ClientOptions options);
  /// With the readers and writers made by `endpoints` (endpoint_creator.hpp).
  ClientCore(ClientOptions options, const EndpointCreator& endpoints);
  ~ClientCore();
  ClientCore(const ClientCore&) = delete;
  ClientCore& operator=(const ClientCore&) = delete;

  /// Leaves the domain: pending calls end NOT_CONNECTED, callbacks stop. Idempotent.
  void close();

  [[nodiscard]] bool connected() const;
  [[nodiscard]] std::string error() const { return error_; }
  [[nodiscard]] const std::string& client_id() const { return client_id_; }
  /// No command request writer or no reply reader: commands end DENIED.
  [[nodiscard]] bool read_only() const { return !can_command_; }
  [[nodiscard]] CommandTraffic command_traffic() const;
  [[nodiscard]] WatchTraffic watch_traffic() const;
  [[nodiscard]] const ClientOptions& options() const { return options_; }
  [[nodiscard]] std::chrono::milliseconds effective(Timeout timeout) const {
    return timeout > Timeout::zero() ? timeout : options_.default_timeout;
  }

  /// Sends a command; `done` runs exactly once, on some internal thread, and
  /// must not block.
  void call(const HandAddress& hand, msg::CommandType command, std::int32_t value,
            std::uint16_t register_code, Timeout timeout, Done done);
  std::future<Reply> call(const HandAddress& hand, msg::CommandType command, std::int32_t value,
                          std::uint16_t register_code, Timeout timeout);
  /// The local check call() makes first (limits of the contract).
  [[nodiscard]] static Result<void, Reply> check(const HandAddress& hand, msg::CommandType command,
                                                 std::int32_t value);

  /// Sends a group command; `done` runs exactly once, as call()'s does.
  void group_call(GroupCommand command, const std::vector<HandAddress>& hands, std::int32_t value,
                  Timeout timeout, GroupDone done);

  /// A `done` that runs `callback` on the callback thread (after the
  /// callbacks posted before it), or at once where the call ends once the
  /// client is closed.
  template <typename R>
  std::function<void(R)> on_callback_thread(std::function<void(R)> callback) {
    return [this, callback = std::move(callback)](R reply) mutable {
      subscriptions_.post_completion(
          [callback = std::move(callback), reply = std::move(reply)]() mutable {
            callback(std::move(reply));
          });
    };
  }

  [[nodiscard]] std::vector<ServiceInfo> services() const;
  [[nodiscard]] std::optional<ServiceInfo> service(std::string_view name) const;
  [[nodiscard]] std::vector<HandStatus> hands() const;
  [[nodiscard]] std::optional<HandStatus> status(const HandAddress& address) const;
  [[nodiscard]] std::vector<KnownHand> known_hands() const;

  Found<ServiceInfo> wait_for_service(std::string_view name, Timeout timeout);
  bool wait_for_statuses(Timeout timeout);
  Found<HandAddress> wait_for_hand(const HandSpec& spec, Timeout timeout);
  std::optional<HandStatus> wait_status(const HandAddress& address,
                                        const std::function<bool(const HandStatus&)>& pred,
                                        Timeout timeout);

  std::shared_ptr<SubscriptionState> subscribe_events(EventCallback callback,
                                                      std::optional<HandAddress> only);
  std::shared_ptr<SubscriptionState> subscribe_status(StatusCallback callback,
                                                      std::optional<HandAddress> only);
  void unsubscribe(const std::shared_ptr<SubscriptionState>& state);
  [[nodiscard]] bool on_dispatcher_thread() const { return subscriptions_.on_dispatcher_thread(); }

  // From the DDS listeners (client_endpoints.hpp). `prefix`: a participant's GUID
  // prefix in hex, as client_id_for() spells it.
  void on_participant_found(const std::string& prefix, const std::string& name);
  void on_participant_left(const std::string& prefix);
  void on_matched(ServiceTracker::Endpoint endpoint, const std::string& prefix, bool matched);
  void on_info(const std::string& prefix, const msg::ServiceInfo& info);
  void on_status(const std::string& prefix, const msg::HandStatus& status);
  void on_event(const std::string& prefix, const msg::HandEvent& event);
  /// A service's owner claim (dh3/contract/ownership.hpp), and its writer's liveliness.
  void on_owner(const std::string& prefix, const msg::ServiceOwner& claim);
  /// `change`: the LivelinessChangedStatus's alive_count_change (not 0).
  void on_owner_liveliness(const std::string& prefix, int change);
  /// A reply written by `prefix`: taken only from the service the call went to.
  void on_reply(const std::string& prefix, const msg::CommandReply& reply);
  void on_group_reply(const msg::GroupReply& reply);

 private:
  /// A subscription of this client to `only` (or every hand), not yet added.
  std::shared_ptr<SubscriptionState> new_subscription(std::optional<HandAddress> only);
  /// Adds `state` by `add`, under mutex_; after close() it is not added but
  /// made inactive.
  std::shared_ptr<SubscriptionState> add_subscription(std::shared_ptr<SubscriptionState> state,
                                                      const std::function<void()>& add);
  using Clock = PendingCalls::Clock;
  /// What a state change leads to, done after `mutex_` is released.
  struct Actions {
    std::vector<PendingCalls::Completion> completions;
    bool wake_io = false;
  };

  Result<void, std::string> set_up(const EndpointCreator& creator);
  /// False for a service (or bus) outside what options_.follow names.
  [[nodiscard]] bool followed(std::string_view service, std::string_view bus = {}) const;
  [[nodiscard]] std::string closed_message() const;

  // The io thread and request writing.
  void io_loop();
  /// Writes the queued requests, unlocking `lock` around each write.
  void write_requests(std::unique_lock<std::mutex>& lock);
  /// Files a call made by call() or group_call() (its request without
  /// client_id and request_seq yet) and writes its request now if it may.
  void submit(PendingCalls::Call call);
  /// Writes one pending request (`mutex_` not held; counted in flight); ends
  /// the call if the write fails.
  void write_request(const PendingCalls::Write& write);
  void run(Actions& actions);

  // All *_locked: `mutex_` held.
  /// Ends the lost incarnation's calls and takes its hands offline, then
  /// hands the service's waiting calls to its new incarnation if ready.
  void apply_locked(const ServiceTracker::Outcome& outcome, Actions& out);
  void dispatch_locked(const std::string& service, Actions& out);
  /// Caches a status sample from `incarnation` and posts it if it is news.
  void take_status_locked(const std::string& incarnation, const msg::HandStatus& sample);
  /// Posts a status just cached, and the ONLINE event it may owe (client_made_events.hpp).
  void post_status_locked(const std::string& incarnation, const HandStatus& status);

  const ClientOptions options_;
  /// What options_.follow names (empty service: everything); set up before
  /// the readers and constant after.
  std::optional<contract::Follow> follow_;
  std::string error_;
  std::string client_id_;
  std::unique_ptr<ClientEndpoints> endpoints_;
  // Set while the participant is set up and constant after. Atomic: the DDS
  // listeners of the readers created first may already look at them.
  std::atomic<bool> can_command_{true};      ///< request writer and reply reader exist
  std::atomic<bool> has_info_reader_{true};  ///< ServiceInfo is readable
  std::atomic<bool> can_group_{false};       ///< group request writer and reply reader exist
  std::atomic<bool> can_administer_{false};  ///< admin request writer and reply reader exist
  std::string denied_message_;  ///< why commands end DENIED; read only once constructed
  std::string admin_denied_message_;  ///< why administrative commands do; likewise

  mutable std::mutex mutex_;             ///< the state mutex (see the top of this file)
  std::condition_variable changed_;      ///< services, statuses, closing
  std::condition_variable io_wake_;      ///< new request to write, new deadline, closing
  std::condition_variable writes_done_;  ///< a write in flight ended
  bool closed_ = false;
  bool io_kick_ = false;  ///< a new deadline for the io thread to see
  ServiceTracker tracker_;
  StatusCache cache_;
  PendingCalls calls_;
  ClientMadeEvents made_events_;

  Subscriptions subscriptions_;  ///< own mutex, after mutex_

  std::atomic<std::uint64_t> requests_written_{0};
  std::atomic<std::uint64_t> own_replies_{0};
  std::atomic<std::uint64_t> foreign_replies_taken_{0};  ///< got past the reply filter
  std::atomic<std::uint64_t> statuses_taken_{0};
  std::atomic<std::uint64_t> events_taken_{0};
  std::atomic<std::uint64_t> infos_taken_{0};
  /// Statuses, events, infos and replies from a participant that does not own
  /// the service name they carry (a duplicate, a standby, an outranked owner).
  std::atomic<std::uint64_t> not_owner_samples_{0};

  std::thread io_thread_;
};

}  // namespace dh3::detail
