#pragma once
// libdh3client: find DH-3 hands on a DDS domain and drive them.
//
//   dh3::ClientOptions options;             // C++17: no designated initializers
//   options.domain = 0;
//   dh3::Client client(options);
//   auto hand = client.wait_for_hand("cell/bus0/1", std::chrono::seconds(5));
//   if (!hand) { std::cerr << hand.message() << "\n"; return 1; }
//   if (auto r = hand->initialize(); !r) std::cerr << dh3::to_string(r.code) << ": " << r.message;
//   auto grasp = hand->grasp(40);           // grasp.grasp == GraspOutcome::grasped or missed
//   auto later = hand->move_to_async(100);  // std::future<Reply>
//   auto done = [](dh3::Reply r) { std::cout << dh3::to_string(r.code) << "\n"; };
//   hand->release_async(100, done);         // done(reply) on the client's callback thread
//
// Every command has three forms: blocking, returning a std::future, and
// taking a completion callback (NAME_async(..., callback, timeout)). Each has
// a timeout (zero: the client's default_timeout) and always ends, once: with
// the service's reply, or with the client's own code (NO_SERVICE, NO_REPLY,
// SERVICE_LOST, NOT_CONNECTED) and a message. Nothing in the data path throws.
// No form starts a thread: every call waits for its reply on the client's own.
//
// Threads: a Client and its Hands may be used from any number of threads at
// once. Event, status and completion callbacks run on one thread of the
// client, one at a time, in the order the client took what they report (the
// status a reply carries comes before that call's completion); they may call
// into the client (even blocking calls, which only delay later callbacks). A
// callback that throws is ignored. A std::future is fulfilled on whichever
// internal thread ended the call, so waiting for one inside a callback is
// fine. Closing the client ends its pending calls NOT_CONNECTED and runs their
// callbacks before close returns (after, when it is called from a callback);
// a call made on a closed client runs its callback at once, on the calling
// thread.
//
// When the reply to a command that changed the hand's state (a force, a
// position reached, a lease) arrives, this client's cached status of that hand
// (Hand::status(), Client::status()) already shows the change: the reply
// carries the hand's status sample, which the service publishes on the status
// topic only after the reply, and the client caches it before the call ends.
// Status callbacks get that sample then, once: the same sample arriving on the
// status topic afterwards, or an older one, is not news and changes nothing.
// So the cache and the status callbacks only move forward (update_seq rises,
// except when the service restarts, which starts it again); like the status
// topic itself (KEEP_LAST 1 per hand), a callback may skip a sample that a
// newer one overtook, never the newest.
//
// When a service leaves the domain (stopped, killed, network lost) its pending
// calls end with SERVICE_LOST and its hands are reported offline; calls made
// while it is away wait (within their timeout) for it to return. When it comes
// back under the same name the same Hand objects work again.

#include <chrono>
#include <cstdint>
#include <functional>
#include <future>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dh3/address.hpp"
#include "dh3/export.hpp"
#include "dh3/group.hpp"
#include "dh3/types.hpp"

namespace dh3 {

namespace detail {
class ClientCore;
struct SubscriptionState;
}  // namespace detail

/// Zero: use the client's default_timeout.
using Timeout = std::chrono::milliseconds;
/// A call's completion callback: called once, with the reply (see "Threads" above).
using ReplyCallback = std::function<void(Reply)>;
using GroupReplyCallback = std::function<void(GroupReply)>;

struct ClientOptions {
  /// DDS domain id, 0-232.
  int domain = 0;
  /// The program named in the DDS participant's name, "<program>@<host>": how
  /// tools that list participants and a hand's lease holder show this client.
  /// Empty: this process's program name. A name with an '@' is announced as it is.
  std::string participant_name;
  /// A Fast DDS XML profiles file. When given, its participant profile (the one
  /// named by `xml_profile`, or the file's default profile) decides the
  /// participant's QoS and transports; `interfaces`, `udp_only` and
  /// `shared_memory` are ignored.
  std::string xml_profile_file;
  std::string xml_profile;
  /// IPv4 addresses of the network interfaces to use; empty = loopback only
  /// (the project's default: nothing leaves the machine unless asked); {"*"} = all.
  std::vector<std::string> interfaces;
  /// UDP only, no shared memory: the default; kept for programs that ask for it.
  bool udp_only = false;
  /// Also Fast DDS's shared-memory transport between processes on this host.
  /// Off by default: Fast DDS 2.9 (Debian 12) has a shared-memory listener
  /// that goes deaf for good once a peer that sent to it exits (fixed in Fast
  /// DDS 2.12.1); UDP on loopback is not slower for dh3's samples
  /// (BENCHMARKS.md). Contradicts udp_only.
  bool shared_memory = false;
  /// Fast DDS discovery servers, each "HOST[:PORT]" (port 11811 by default);
  /// the n-th entry is the server started with id n, an empty entry skips an
  /// id. Empty: ROS_DISCOVERY_SERVER's servers if that is set, otherwise
  /// simple (multicast) discovery. The interfaces must reach the servers.
  std::vector<std::string> discovery_servers;
  /// DDS Security: a directory of credentials in the layout
  /// deploy/security/make-test-pki.sh writes (identity_ca.pem,
  /// permissions_ca.pem, governance.p7s, IDENTITY/{cert.pem,key.pem,
  /// permissions.p7s}). Empty: no security (unless an XML profile enables it).
  /// A secured client sees only services with credentials of the same CAs.
  std::string security_dir;
  /// Which identity's folder in `security_dir` this client uses. An identity
  /// whose permissions do not allow command requests (the test PKI's
  /// "monitor") still connects: it sees statuses and events, and its commands
  /// end at once with DENIED (see Client::read_only()).
  std::string security_identity = "operator";
  /// The timeout of calls and waits that are given none (Timeout{0}).
  std::chrono::milliseconds default_timeout{10'000};
  /// Follow one cell: "SERVICE" or "SERVICE/BUS". The client then knows only
  /// that service (only that bus's hands): it reads statuses, events and
  /// service info in the cell's DDS partition, which only that service
  /// publishes in, and the service filters them for it (a writer-side
  /// content filter, which also picks the bus), so what it receives and
  /// spends does not grow with the other cells of the domain, and it
  /// commands only that service's hands (others end NO_SERVICE). Empty:
  /// every service of the domain. A malformed one leaves the client
  /// unconnected, error() saying why. Needs services of dh3 0.1 from
  /// 2026-11-27 on (older ones publish in the default partition only).
  std::string follow;
};

/// Keeps a callback registered; unsubscribes when destroyed. After
/// unsubscribe() returns the callback is not running and will not run again
/// (unless unsubscribe() was called from inside that same callback, which is
/// allowed: it then returns at once and the callback is not called again).
class DH3_CLIENT_API Subscription {
 public:
  Subscription() = default;
  ~Subscription();
  Subscription(Subscription&& other) noexcept;
  Subscription& operator=(Subscription&& other) noexcept;
  Subscription(const Subscription&) = delete;
  Subscription& operator=(const Subscription&) = delete;

  void unsubscribe();
  [[nodiscard]] bool active() const;

 private:
  friend class Client;
  friend class Hand;
  explicit Subscription(std::shared_ptr<detail::SubscriptionState> state);
  std::shared_ptr<detail::SubscriptionState> state_;
};

using EventCallback = std::function<void(const HandEvent&)>;
using StatusCallback = std::function<void(const HandStatus&)>;

/// A handle on one hand. Cheap to copy; every copy drives the same hand through
/// the same client. A Hand outliving its Client answers NOT_CONNECTED.
class DH3_CLIENT_API Hand {
 public:
  [[nodiscard]] const HandAddress& address() const { return address_; }

  /// The latest status, nullopt until the service published one.
  [[nodiscard]] std::optional<HandStatus> status() const;
  [[nodiscard]] bool online() const;
  /// Waits until the hand's latest status satisfies `pred` (checked at once,
  /// then on every new status); returns that status, nullopt on timeout.
  ///   hand.wait_until([](const dh3::HandStatus& s) { return s.grip == dh3::GripState::grasped; })
  std::optional<HandStatus> wait_until(const std::function<bool(const HandStatus&)>& pred,
                                       Timeout timeout = Timeout::zero()) const;

  /// Initializes the hand; the reply comes once initialization finished.
  std::future<Reply> initialize_async(Timeout timeout = Timeout::zero());
  void initialize_async(ReplyCallback done, Timeout timeout = Timeout::zero());
  Reply initialize(Timeout timeout = Timeout::zero());
  /// Moves the fingers to `position` percent (0 closed - 100 open).
  std::future<Reply> move_to_async(std::int32_t position, Timeout timeout = Timeout::zero());
  void move_to_async(std::int32_t position, ReplyCallback done, Timeout timeout = Timeout::zero());
  Reply move_to(std::int32_t position, Timeout timeout = Timeout::zero());
  /// Rotates to `percent` of 90 degrees.
  std::future<Reply> rotate_to_async(std::int32_t percent, Timeout timeout = Timeout::zero());
  void rotate_to_async(std::int32_t percent, ReplyCallback done, Timeout timeout = Timeout::zero());
  Reply rotate_to(std::int32_t percent, Timeout timeout = Timeout::zero());
  /// Sets the closing (gripping) force and, when given, the opening force, in
  /// percent (20-100). With both, the first failure is the reply.
  std::future<Reply> set_force_async(std::int32_t closing, std::optional<std::int32_t> opening,
                                     Timeout timeout = Timeout::zero());
  void set_force_async(std::int32_t closing, std::optional<std::int32_t> opening,
                       ReplyCallback done, Timeout timeout = Timeout::zero());
  Reply set_force(std::int32_t closing, std::optional<std::int32_t> opening = std::nullopt,
                  Timeout timeout = Timeout::zero());
  /// Closes with `force` percent: reply.grasp is GRASPED (stopped on an
  /// object) or MISSED (closed on nothing); reply.value the final position.
  std::future<Reply> grasp_async(std::int32_t force, Timeout timeout = Timeout::zero());
  void grasp_async(std::int32_t force, ReplyCallback done, Timeout timeout = Timeout::zero());
  Reply grasp(std::int32_t force, Timeout timeout = Timeout::zero());
  /// Opens to `position`; the reply comes once arrived.
  std::future<Reply> release_async(std::int32_t position, Timeout timeout = Timeout::zero());
  void release_async(std::int32_t position, ReplyCallback done, Timeout timeout = Timeout::zero());
  Reply release(std::int32_t position, Timeout timeout = Timeout::zero());
  /// Holds the current position; pending motion ends CANCELLED.
  std::future<Reply> stop_async(Timeout timeout = Timeout::zero());
  void stop_async(ReplyCallback done, Timeout timeout = Timeout::zero());
  Reply stop(Timeout timeout = Timeout::zero());
  /// Reads a register (dh3::reg::position, ...); reply.value is what was read.
  std::future<Reply> read_async(std::uint16_t register_code, Timeout timeout = Timeout::zero());
  void read_async(std::uint16_t register_code, ReplyCallback done,
                  Timeout timeout = Timeout::zero());
  Reply read(std::uint16_t register_code, Timeout timeout = Timeout::zero());
  /// Administrative (the service must allow it; the hand needs a reboot after).
  /// Sent on the admin request topic: under DDS Security only an identity
  /// whose permissions grant it may (an operator's ends DENIED at once).
  std::future<Reply> set_can_id_async(std::int32_t can_id, Timeout timeout = Timeout::zero());
  void set_can_id_async(std::int32_t can_id, ReplyCallback done, Timeout timeout = Timeout::zero());
  Reply set_can_id(std::int32_t can_id, Timeout timeout = Timeout::zero());
  /// Administrative: baud rate index 0 (500 kbps) - 5 (100 kbps).
  std::future<Reply> set_baud_rate_async(std::int32_t index, Timeout timeout = Timeout::zero());
  void set_baud_rate_async(std::int32_t index, ReplyCallback done,
                           Timeout timeout = Timeout::zero());
  Reply set_baud_rate(std::int32_t index, Timeout timeout = Timeout::zero());

  /// Probes this hand's whole bus for hands now; reply.found_ids lists them.
  std::future<Reply> scan_bus_async(Timeout timeout = Timeout::zero());
  void scan_bus_async(ReplyCallback done, Timeout timeout = Timeout::zero());
  Reply scan_bus(Timeout timeout = Timeout::zero());

  /// Leases: while this client holds one, other clients' motion and write
  /// commands to the hand are DENIED. A lease ends on release, on expiry, or
  /// when this client leaves the domain.
  std::future<Reply> acquire_lease_async(std::chrono::milliseconds ttl,
                                         Timeout timeout = Timeout::zero());
  void acquire_lease_async(std::chrono::milliseconds ttl, ReplyCallback done,
                           Timeout timeout = Timeout::zero());
  Reply acquire_lease(std::chrono::milliseconds ttl, Timeout timeout = Timeout::zero());
  std::future<Reply> renew_lease_async(std::chrono::milliseconds ttl,
                                       Timeout timeout = Timeout::zero());
  void renew_lease_async(std::chrono::milliseconds ttl, ReplyCallback done,
                         Timeout timeout = Timeout::zero());
  Reply renew_lease(std::chrono::milliseconds ttl, Timeout timeout = Timeout::zero());
  std::future<Reply> release_lease_async(Timeout timeout = Timeout::zero());
  void release_lease_async(ReplyCallback done, Timeout timeout = Timeout::zero());
  Reply release_lease(Timeout timeout = Timeout::zero());

  /// Calls `callback` for each event of this hand from now on.
  Subscription subscribe(EventCallback callback);

 private:
  friend class Client;
  Hand(std::shared_ptr<detail::ClientCore> core, HandAddress address);
  std::shared_ptr<detail::ClientCore> core_;
  HandAddress address_;
};

/// What reached this client over DDS for its commands, since it was created
/// (diagnostics and benchmarks).
struct CommandTraffic {
  std::uint64_t requests_written = 0;
  /// Replies carrying this client's id.
  std::uint64_t own_replies = 0;
  /// Replies to other clients that reached this client and were dropped here.
  /// A dh3 service sends each dh3 client only its own command replies, and
  /// the client reads replies VOLATILE, so none of those the service keeps
  /// from before it joined. Group replies travel unfiltered: those of other
  /// clients' groups written while this client is connected count here.
  std::uint64_t foreign_replies = 0;
};

/// What reached this client of the watched topics (statuses, events, service
/// info) since it was created (diagnostics, tests and benchmarks).
struct WatchTraffic {
  std::uint64_t statuses = 0;  ///< status samples taken (before the newest-only check)
  std::uint64_t events = 0;
  std::uint64_t infos = 0;
  /// Samples that reached a following client from another cell and were
  /// dropped on arrival: a writer did not filter them for it (a service's
  /// kept statuses as the client joins, the last of each hand, once; a
  /// writer that does not know dh3's filter). 0 for a client that follows nothing.
  std::uint64_t dropped_on_arrival = 0;
  /// Statuses, events, service infos and replies ignored because their writer
  /// does not own the service name they carry: a second service of that name,
  /// a standby, or one another outranked (docs/failover.md). 0 in a healthy cell.
  std::uint64_t not_owner = 0;
};

class DH3_CLIENT_API Client {
 public:
  /// Joins the DDS domain. Never throws: check connected() and error().
  explicit Client(ClientOptions options = {});
  /// Leaves the domain; pending calls end NOT_CONNECTED, callbacks stop.
  ~Client();
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;

  /// False if the DDS participant could not be created; error() says why.
  [[nodiscard]] bool connected() const;
  [[nodiscard]] std::string error() const;
  /// True when this client may not send commands: DDS Security refused it the
  /// command request writer or the reply reader (a read-only identity).
  /// Statuses, events and hand lookups work; every command ends at once with
  /// DENIED. Services are then known from their statuses and events only (no
  /// ServiceInfo unless the identity may read it).
  [[nodiscard]] bool read_only() const;
  /// This client's id in requests (its participant's GUID prefix in hex).
  [[nodiscard]] std::string client_id() const;
  [[nodiscard]] int domain() const;
  [[nodiscard]] std::chrono::milliseconds default_timeout() const;
  [[nodiscard]] CommandTraffic command_traffic() const;
  [[nodiscard]] WatchTraffic watch_traffic() const;

  /// Every service seen on the domain, by name (ready says which are here now).
  [[nodiscard]] std::vector<ServiceInfo> services() const;
  [[nodiscard]] std::optional<ServiceInfo> service(std::string_view name) const;
  /// The latest status of every hand seen (late joiners get them at once).
  [[nodiscard]] std::vector<HandStatus> hands() const;
  [[nodiscard]] std::optional<HandStatus> status(const HandAddress& address) const;

  /// Waits until the named service (empty: any service) is ready, i.e. calls
  /// to it go out at once. NO_SERVICE on timeout.
  Found<ServiceInfo> wait_for_service(std::string_view name = {},
                                      Timeout timeout = Timeout::zero());
  /// Waits until every ready service's hands (as its info lists them) have a
  /// status here; true if so before the timeout.
  bool wait_for_statuses(Timeout timeout = Timeout::zero());

  /// A hand by address; no lookup, no waiting.
  Hand hand(const HandAddress& address);
  /// A hand by any form parse_hand_spec() accepts, among the hands known now.
  Found<Hand> find_hand(std::string_view spec);
  /// Waits until `spec` names exactly one hand whose status this client has.
  /// NO_SERVICE if its service never appeared, UNKNOWN_HAND if the service is
  /// here but has no such hand, INVALID_ARGUMENT for bad or ambiguous specs.
  Found<Hand> wait_for_hand(std::string_view spec, Timeout timeout = Timeout::zero());

  /// Probes a bus for hands now; reply.found_ids lists those that answered.
  std::future<Reply> scan_async(const std::string& service, const std::string& bus,
                                Timeout timeout = Timeout::zero());
  void scan_async(const std::string& service, const std::string& bus, ReplyCallback done,
                  Timeout timeout = Timeout::zero());
  Reply scan(const std::string& service, const std::string& bus, Timeout timeout = Timeout::zero());

  /// One command for several hands of one service, together and all or none
  /// (dh3/group.hpp):
  ///   auto r = client.group(dh3::GroupCommand::grasp, {left, right}, 50);
  ///   // r.hands[i].grasp for each; r.message names every hand that failed
  /// `timeout` bounds the whole call (and each hand's command on the service).
  std::future<GroupReply> group_async(GroupCommand command, std::vector<HandAddress> hands,
                                      std::int32_t value = 0, Timeout timeout = Timeout::zero());
  void group_async(GroupCommand command, std::vector<HandAddress> hands, std::int32_t value,
                   GroupReplyCallback done, Timeout timeout = Timeout::zero());
  GroupReply group(GroupCommand command, const std::vector<HandAddress>& hands,
                   std::int32_t value = 0, Timeout timeout = Timeout::zero());

  /// Calls `callback` for every event of every hand (or of `only`) from now on.
  Subscription subscribe(EventCallback callback, std::optional<HandAddress> only = std::nullopt);
  /// Calls `callback` for every new status sample (including the late-joiner
  /// ones already received, delivered first) of every hand or of `only`.
  Subscription subscribe_status(StatusCallback callback,
                                std::optional<HandAddress> only = std::nullopt);

 private:
  std::shared_ptr<detail::ClientCore> core_;
};

}  // namespace dh3
