#pragma once
// What dh3::Client and dh3::Hand share: the DDS participant and everything the
// client knows (services, hand statuses, pending calls, subscriptions).
//
// Threads and who does what:
//   - Fast DDS listener threads deliver samples, matches and participant
//     changes; they update the state under `mutex_` and never write to DDS.
//   - The calling thread writes its request itself when the service is ready
//     and no other request is queued or being written (so the requests of one
//     thread keep their order); otherwise, and for calls made on a DDS
//     listener thread (a call chained from a reply), the internal "io" thread
//     writes it. close() waits for writes in progress before it deletes the
//     DDS entities. The io thread also ends calls whose deadline passed; a call
//     wakes it only when its deadline comes before the io thread's next wake.
//   - One dispatcher thread runs user callbacks (events, statuses), in order.
//     User code never runs on a DDS thread, so a callback that makes a
//     blocking call cannot hold up the very reply it waits for.
//
// A service "incarnation" is the DDS participant that serves it (its GUID
// prefix). When two participants claim one name, the one whose ServiceInfo
// says it started later is current: discovery order says nothing (the new
// instance of a killed service may be discovered before the client hears the
// last of the old one). The service is ready once that participant has matched our request
// writer, reply reader and event reader: a call is written only then (a
// request written earlier would be lost: the topics are volatile), and a
// program that waited for a ready service gets every event from then on. When the incarnation
// leaves the domain, or a newer one of the same name appears (a restart), the calls written to the
// old one end SERVICE_LOST and its hands go offline; calls not yet written wait for the next
// incarnation until their deadline.
//
// One file per job: client_endpoints (DDS wiring and listeners), pending_calls
// (calls, the io thread), service_tracker (incarnations, restarts, losses),
// status_cache (what the client knows and the waits on it), subscriptions
// (user callbacks), dispatcher (the callback thread), client_core (life cycle).
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
#include <deque>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "dh3/address.hpp"
#include "dh3/base/result.hpp"
#include "dh3/client.hpp"
#include "dh3/types.hpp"
#include "dh3_idl/dh3.h"
#include "dispatcher.hpp"

namespace dh3::detail {

/// True on a thread that runs a Fast DDS listener of this library
/// (client_endpoints.hpp sets it): such a thread does not write requests.
inline thread_local bool t_on_dds_listener = false;

/// Marks the current thread as a DDS listener's while it lives.
class OnDdsListener {
 public:
  OnDdsListener() : was_(t_on_dds_listener) { t_on_dds_listener = true; }
  ~OnDdsListener() { t_on_dds_listener = was_; }
  OnDdsListener(const OnDdsListener&) = delete;
  OnDdsListener& operator=(const OnDdsListener&) = delete;

 private:
  bool was_;
};

inline Reply make_reply(Code code, std::string message) {
  Reply reply;
  reply.code = code;
  reply.message = std::move(message);
  return reply;
}

struct SubscriptionState {
  std::mutex run_mutex;  ///< held while the callback runs
  std::atomic<bool> active{true};
  EventCallback on_event;
  StatusCallback on_status;
  std::optional<HandAddress> only;
  std::weak_ptr<ClientCore> core;
};

class EndpointCreator;

class ClientCore : public std::enable_shared_from_this<ClientCore> {
 public:
  using Done = std::function<void(Reply)>;

  explicit ClientCore(ClientOptions options);
  /// With the readers and writers made by `endpoints` (client_endpoints.hpp).
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

  /// A group command (group_calls.cpp); blocks until its reply or deadline.
  GroupReply group_call(GroupCommand command, const std::vector<HandAddress>& hands,
                        std::int32_t value, Timeout timeout);

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
  [[nodiscard]] bool on_dispatcher_thread() const { return dispatcher_.on_dispatcher_thread(); }

  // From the DDS listeners (client_endpoints.hpp). `prefix`: a participant's GUID
  // prefix in hex, as client_id_for() spells it.
  void on_participant_found(const std::string& prefix, const std::string& name);
  void on_participant_left(const std::string& prefix);
  void on_request_reader_matched(const std::string& prefix, bool matched);
  void on_reply_writer_matched(const std::string& prefix, bool matched);
  void on_event_writer_matched(const std::string& prefix, bool matched);
  void on_info(const std::string& prefix, const msg::ServiceInfo& info);
  void on_status(const std::string& prefix, const msg::HandStatus& status);
  void on_event(const std::string& prefix, const msg::HandEvent& event);
  void on_reply(const msg::CommandReply& reply);
  void on_group_reply(const msg::GroupReply& reply);
  void on_group_request_reader_matched(const std::string& prefix, bool matched);
  void on_group_reply_writer_matched(const std::string& prefix, bool matched);

 private:
  struct Dds;
  using Clock = std::chrono::steady_clock;

  struct Pending {
    HandAddress hand;
    msg::CommandRequest request;
    Clock::time_point deadline;
    std::chrono::milliseconds timeout{};
    Done done;
    std::string sent_to;  ///< the incarnation it was written to; empty: not yet written
  };
  struct Participant {
    std::string service;
    bool alive = true;
    bool has_info = false;         ///< its ServiceInfo arrived
    std::uint64_t started_ns = 0;  ///< from its ServiceInfo
  };
  struct ServiceState {
    std::string incarnation;  ///< current participant's prefix; empty until known
    bool alive = false;
    std::optional<ServiceInfo> info;
  };
  /// What a state change leads to, done after `mutex_` is released.
  struct Actions {
    std::vector<std::pair<Done, Reply>> completions;
    bool wake_io = false;
  };

  // DDS wiring (client_endpoints.cpp).
  Result<void, std::string> set_up_dds(const EndpointCreator& creator);
  [[nodiscard]] static std::string denied_message(const ClientOptions& options);
  // Pending calls (pending_calls.cpp).
  void io_loop();
  void write_requests_locked(std::unique_lock<std::mutex>& lock);
  /// Writes one pending request (`mutex_` not held; writes_in_flight_ counts
  /// it); ends the call if the write fails.
  void write_request(std::uint64_t seq, const msg::CommandRequest& request);
  void run(Actions& actions);
  [[nodiscard]] Reply expired_locked(const Pending& pending) const;
  /// Says in each NO_REPLY among `expired` whether the services' request
  /// readers acknowledged every request written, so a caller knows whether
  /// the service may have run it (`mutex_` not held: it asks the writer).
  void tell_acknowledgment(std::vector<std::pair<Done, Reply>>& expired) const;
  // Group calls (group_calls.cpp).
  [[nodiscard]] bool group_ready_locked(const std::string& service) const;
  /// Ends every pending group call with NOT_CONNECTED (close()).
  void close_group_calls_locked();
  // Following services (service_tracker.cpp).
  /// False for a service (or bus) outside what options_.follow names.
  [[nodiscard]] bool followed(std::string_view service, std::string_view bus = {}) const;
  void on_match(std::multiset<std::string>& set, const std::string& prefix, bool matched);

  // All *_locked: `mutex_` held. Following services (service_tracker.cpp):
  [[nodiscard]] bool ready_locked(const std::string& service) const;
  [[nodiscard]] bool prefix_is_dead_locked(const std::string& prefix) const;
  /// Records that `prefix` serves `service`; makes it the current incarnation
  /// if the service has no live one. False if the participant is known dead.
  bool note_participant_locked(const std::string& prefix, const std::string& service, Actions& out);
  void make_current_locked(const std::string& service, const std::string& prefix, Actions& out);
  void dispatch_locked(const std::string& service, Actions& out);
  void lose_locked(const std::string& service, const std::string& why, Actions& out);
  // Subscriptions (subscriptions.cpp).
  void post_status_locked(const HandStatus& status);
  void post_event_locked(const HandEvent& event);
  // What the client knows (status_cache.cpp).
  /// Takes a status sample from `prefix` (an incarnation), from the status
  /// topic or a reply: cached and posted to the status subscriptions only if
  /// newer than the cached one (see statuses_); false if not.
  bool take_status_locked(const std::string& prefix, const msg::HandStatus& sample);
  [[nodiscard]] ServiceInfo info_locked(const std::string& name, const ServiceState& s) const;
  [[nodiscard]] std::vector<KnownHand> known_hands_locked() const;

  const ClientOptions options_;
  /// What options_.follow names (empty service: everything); set up before
  /// the readers and constant after.
  std::string follow_service_;
  std::string follow_bus_;
  std::string error_;
  std::string client_id_;
  std::unique_ptr<Dds> dds_;
  // Set while the participant is set up and constant after. Atomic: the DDS
  // listeners of the readers created first may already look at them.
  std::atomic<bool> can_command_{true};      ///< request writer and reply reader exist
  std::atomic<bool> has_info_reader_{true};  ///< ServiceInfo is readable
  std::string denied_message_;  ///< why commands end DENIED; read only once constructed

  mutable std::mutex mutex_;
  std::condition_variable changed_;  ///< services, statuses, closing
  std::condition_variable io_wake_;  ///< new request to write, new deadline, closing
  bool closed_ = false;
  bool io_kick_ = false;  ///< a new deadline for the io thread to see
  /// When the io thread will wake next on its own (max: only when kicked).
  Clock::time_point io_wake_at_ = Clock::time_point::max();
  /// Requests being written now, by callers or the io thread.
  int writes_in_flight_ = 0;
  std::condition_variable writes_done_;
  std::uint64_t last_seq_ = 0;
  std::map<std::uint64_t, Pending> pending_;
  std::deque<std::uint64_t> to_write_;               ///< request_seqs for the io thread
  std::map<std::string, Participant> participants_;  ///< service participants, by prefix
  std::map<std::string, ServiceState, std::less<>> services_;
  std::multiset<std::string> request_readers_;  ///< prefixes of matched request readers
  std::multiset<std::string> reply_writers_;    ///< prefixes of matched reply writers
  std::multiset<std::string> event_writers_;    ///< prefixes of matched event writers
  /// The newest status of every hand. A hand's status comes twice, in the
  /// reply to a command (CommandReply.status, the service's sample before it
  /// is written) and on the status topic, in either order: a sample from the
  /// incarnation that sent the cached one replaces it only with a higher
  /// update_seq, so each sample is cached and posted once, in order, and an
  /// older one never rolls the cache back. update_seq restarts with the
  /// service: a sample of another incarnation always replaces the cached one.
  std::map<HandAddress, HandStatus> statuses_;
  std::map<HandAddress, std::string> status_origins_;  ///< the incarnation of each cached status
  std::vector<std::shared_ptr<SubscriptionState>> event_subs_;
  std::vector<std::shared_ptr<SubscriptionState>> status_subs_;

  /// Group calls waiting for their reply, by request_seq (group_calls.cpp).
  std::map<std::uint64_t, std::shared_ptr<std::promise<GroupReply>>> group_pending_;
  std::multiset<std::string> group_request_readers_;  ///< prefixes of matched group readers
  std::multiset<std::string> group_reply_writers_;    ///< prefixes of matched group writers

  std::atomic<std::uint64_t> requests_written_{0};
  std::atomic<std::uint64_t> own_replies_{0};
  std::atomic<std::uint64_t> foreign_replies_taken_{0};  ///< got past the reply filter
  std::atomic<std::uint64_t> statuses_taken_{0};
  std::atomic<std::uint64_t> events_taken_{0};
  std::atomic<std::uint64_t> infos_taken_{0};

  Dispatcher dispatcher_;
  std::thread io_thread_;
};

}  // namespace dh3::detail
