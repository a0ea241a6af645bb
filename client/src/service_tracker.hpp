#pragma once
// Which participant serves each service now (its incarnation), when it is
// ready to take requests, and when a restart or a departure loses it.
//
// Not thread-safe: ClientCore keeps it under its state mutex, with the calls and
// statuses a loss changes. Knows no DDS: participants are GUID prefixes in hex.
//
// Once a service's owner claims are known (dh3/contract/ownership.hpp), the owner is
// current and nothing else of that name is believed: its statuses, events,
// infos and replies are ignored. An owner whose liveliness lapses (killed,
// frozen, cut off) is lost at once; one that asserts again is current again.
// Before any claim is known, the participant whose ServiceInfo says it
// started later is current: discovery order says nothing (the new instance of
// a killed service may be discovered before the client hears the last of the
// old one). The service is ready once that participant has matched our request
// writer, reply reader and event reader (only the event reader for a read-only
// client), and, if we read owner claims, once its liveliness was seen: a death
// just after we said ready must not be left to the participant lease. A
// service whose owner writer never shows (its permissions predate the topic)
// is ready kOwnerWait after the rest matched, and its death is seen late.

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "dh3/contract/ownership.hpp"
#include "dh3/types.hpp"
#include "lapse_judge.hpp"

namespace dh3::detail {

class ServiceTracker {
 public:
  /// The endpoints of a service's participant that match ours.
  enum class Endpoint : std::uint8_t {
    request_reader,
    reply_writer,
    event_writer,
    group_request_reader,
    group_reply_writer,
    owner_writer,
    admin_request_reader
  };
  /// What a change means for the calls and hands of `service`, in this order:
  /// the incarnation `lost` (if not empty) is gone for `why`, then the calls
  /// waiting for the service may go out if it is ready.
  struct Outcome {
    std::string service;
    std::string lost;
    std::string why;
    bool lost_service = false;  ///< its hands go offline (also when `lost` is empty)
    /// The calls sent to `lost` stay pending: a lapse ends them only later.
    bool keep_calls = false;
    /// The calls sent to this incarnation end now, for `why` (a lapse stood).
    std::string end_calls_of;
    /// An incarnation lost for a lapse that asserts again (a frozen service
    /// continued, a cut-off one reached again): its hands come back.
    std::string regained;
    bool may_dispatch = false;
    /// The service is now served by another process than before (a standby
    /// took over, a restart, a higher-ranking owner): who served it, and
    /// who serves it now, in words; empty if it did not change hands.
    std::string taken_over_from;
    std::string taken_over_by;
  };

  /// How long a service whose other endpoints matched waits for its owner
  /// writer's liveliness before it is ready without it.
  static constexpr std::chrono::milliseconds kOwnerWait{2000};

  /// For a read-only client (no request writer or reply reader) a service is
  /// ready once its events reach it. One that reads owner claims waits for
  /// the service's liveliness too (or kOwnerWait). Matches may come before
  /// this is called (`now`): the waits of the participants known start then.
  void set_endpoints(bool can_command, bool has_owner_reader,
                     std::chrono::steady_clock::time_point now = std::chrono::steady_clock::now());

  /// Records that `prefix` serves `service`; makes it current if the service
  /// has no live incarnation. False if that participant is known to be gone.
  bool note_participant(
      const std::string& prefix, const std::string& service, Outcome& out,
      std::chrono::steady_clock::time_point now = std::chrono::steady_clock::now());
  /// Discovery found participant `prefix`, which announces `service`. One
  /// that had left is back: Fast DDS drops a live participant whose
  /// announcements did not reach this process for a lease (a starved process,
  /// a cut cable) and finds it again at its next announcement, under the same
  /// prefix. False if an owner claim says another participant serves the name.
  bool participant_found(
      const std::string& prefix, const std::string& service, Outcome& out,
      std::chrono::steady_clock::time_point now = std::chrono::steady_clock::now());
  /// The participant left the domain; its service is lost if it was current,
  /// and another live participant of that name takes over.
  Outcome participant_left(const std::string& prefix);
  /// A ServiceInfo from `prefix`. False if ignored (the participant is gone,
  /// or an older instance still around while the newer is current).
  bool take_info(const std::string& prefix, ServiceInfo info, Outcome& out);
  /// An owner claim written by `prefix` (its sample arrived at `now`). A
  /// claimant whose liveliness is never seen is taken as lapsed a lease after
  /// its claim: a service killed before its first assertion reached us.
  void take_claim(const contract::OwnerClaim& claim, Outcome& out,
                  std::chrono::steady_clock::time_point now = std::chrono::steady_clock::now());
  /// Fast DDS changed the liveliness of the owner writer of `prefix` by
  /// `change`: whether it is alive now, by the sum of the changes, whatever
  /// order they came in (contract::OwnerTable::liveliness_changed). The caller
  /// then calls owner_alive() or owner_lapsed().
  bool owner_liveliness_changed(const std::string& prefix, int change) {
    return owners_.liveliness_changed(prefix, change);
  }
  /// A hand status `prefix` published for `service`: as note_participant(),
  /// and proof of life for an owner whose liveliness Fast DDS never reported.
  /// Fast DDS 2.9 can drop a reader's first liveliness report of a writer
  /// (seen: a dh3ctl whose owner claim came, its first report never, under
  /// load in user-mode Linux), and reports nothing more while the writer
  /// keeps asserting; the lapse take_claim() then assumed stands for good,
  /// while the owner's statuses keep coming. One that arrives once that lapse
  /// is believed comes from a live owner: a dead one sent its last before.
  bool note_status(const std::string& prefix, const std::string& service, Outcome& out);
  /// The owner writer of `prefix` asserted its liveliness (true) or missed its
  /// lease (false), taken as final at once.
  Outcome owner_alive(const std::string& prefix, bool alive);
  /// The owner writer of `prefix` missed its lease at `now`. If it has not
  /// asserted again kOwnerLapseConfirm later the service is lost (its hands
  /// offline, no new call sent to it), and its calls in flight end when the
  /// lapse's judge says so (lapse_judge.hpp: then too if this process has
  /// read all it received); asserting again undoes what is left.
  void owner_lapsed(const std::string& prefix, std::chrono::steady_clock::time_point now);
  /// How confirm_lapses() looks at this process's receive queues
  /// (receive_queues.hpp); until set, they cannot be seen.
  void set_receive_looker(std::function<ReceiveState()> looker) { look_ = std::move(looker); }
  /// What the lapses that stood until `now` mean, and the services ready
  /// because their owner writer's wait (kOwnerWait) ended. Looks at the
  /// receive queues once if a lapse's judge wants a look.
  std::vector<Outcome> confirm_lapses(std::chrono::steady_clock::time_point now);
  /// When the next lapse is to be confirmed or owner wait ends; max() if none.
  [[nodiscard]] std::chrono::steady_clock::time_point next_lapse() const;
  /// True if what `prefix` says about `service` is to be believed: it is the
  /// service's owner, or no owner of the name is known and it is not gone.
  [[nodiscard]] bool believed(const std::string& prefix, std::string_view service) const;

  /// One of our endpoints matched (or unmatched) one of `prefix`'s; returns the
  /// participant's service if it is alive (its waiting calls may go out).
  std::optional<std::string> matched(
      Endpoint endpoint, const std::string& prefix, bool matched,
      std::chrono::steady_clock::time_point now = std::chrono::steady_clock::now());

  [[nodiscard]] bool ready(const std::string& service) const;
  /// Ready, and its group request reader and group reply writer matched ours.
  [[nodiscard]] bool group_ready(const std::string& service) const;
  /// Ready, and its admin request reader matched our admin request writer.
  [[nodiscard]] bool admin_ready(const std::string& service) const;
  /// The current incarnation of `service`; empty if none.
  [[nodiscard]] std::string incarnation(const std::string& service) const;
  [[nodiscard]] bool alive(const std::string& service) const;
  [[nodiscard]] bool any_alive() const;
  [[nodiscard]] bool participant_gone(const std::string& prefix) const;
  /// What discovery showed of `service`, in words for a NO_SERVICE message:
  /// each participant announcing it, and why it is not believed or which of
  /// its endpoints have not matched this client; or that none was found.
  [[nodiscard]] std::string sightings(const std::string& service) const;
  /// The same, and nothing for no name (a wait for any service).
  [[nodiscard]] std::string sightings_if_named(const std::optional<std::string>& service) const {
    return service ? sightings(*service) : std::string();
  }

  /// Every service known, with `ready` filled in.
  [[nodiscard]] std::vector<ServiceInfo> services() const;
  [[nodiscard]] std::optional<ServiceInfo> service(std::string_view name) const;
  /// The first ready service named `name` (any if empty) whose ServiceInfo
  /// arrived, or without one if `need_info` is false.
  [[nodiscard]] std::optional<ServiceInfo> find_ready(std::string_view name, bool need_info) const;
  /// The ServiceInfo (nullopt if none arrived yet) of every ready service, by name.
  [[nodiscard]] std::map<std::string, std::optional<ServiceInfo>> ready_services() const;
  /// The ServiceInfos that arrived.
  [[nodiscard]] std::vector<ServiceInfo> infos() const;

 private:
  struct Participant {
    std::string service;
    bool alive = true;
    bool has_info = false;         ///< its ServiceInfo arrived
    std::uint64_t started_ns = 0;  ///< from its ServiceInfo
    /// Its ServiceInfo, kept while it is not believed: it is sent once
    /// (TRANSIENT_LOCAL), and the service may become the owner later.
    std::optional<ServiceInfo> info;
    /// When it is ready without its owner writer's liveliness; set once its
    /// other endpoints matched (kOwnerWait later).
    std::optional<std::chrono::steady_clock::time_point> owner_wait_until;
    bool owner_waived = false;  ///< that time passed: ready without it
  };
  struct ServiceState {
    std::string incarnation;  ///< current participant's prefix; empty until known
    bool alive = false;
    std::optional<ServiceInfo> info;
  };

  void make_current(const std::string& service, const std::string& prefix, Outcome& out);
  /// A service participant in words: its claim's process and host if known.
  [[nodiscard]] std::string describe(const std::string& prefix) const;
  /// Follows the owner table: the owner of `service` (if any) becomes
  /// current, a current participant that is no longer the owner is lost.
  void follow_owner(const std::string& service, Outcome& out);
  void lose(const std::string& service, const std::string& why, Outcome& out);
  /// The endpoints of `prefix` this client needs that have not matched, in words.
  [[nodiscard]] std::string unmatched(const std::string& prefix) const;
  /// Its request, reply and event endpoints (the event writer only, read-only) matched ours.
  [[nodiscard]] bool endpoints_matched(const std::string& prefix) const;
  /// Starts `prefix`'s wait for its owner's liveliness once its other endpoints matched.
  void start_owner_wait(const std::string& prefix, std::chrono::steady_clock::time_point now);
  [[nodiscard]] ServiceInfo info_of(const std::string& name, const ServiceState& state) const;
  std::multiset<std::string>& set_of(Endpoint endpoint);

  bool can_command_ = true;
  bool owner_reader_ = false;
  std::map<std::string, Participant> participants_;
  /// Every participant discovery found, and the service it announces.
  std::map<std::string, std::string> announced_;  ///< service participants, by prefix
  std::map<std::string, ServiceState, std::less<>> services_;
  contract::OwnerTable owners_;
  /// A lapse reported and not yet final.
  struct Lapse {
    explicit Lapse(std::chrono::steady_clock::time_point reported)
        : confirm_at(reported + contract::kOwnerLapseConfirm), judge(reported) {}
    std::chrono::steady_clock::time_point confirm_at;  ///< the service is lost then
    LapseJudge judge;  ///< when its calls in flight end
    bool believed = false;
    std::string incarnation;  ///< lost, once believed
    std::string why;
  };
  /// Lapsed owner writers whose lapse is not final yet, by prefix.
  std::map<std::string, Lapse> lapses_;
  std::function<ReceiveState()> look_ = [] { return ReceiveState::unknown; };
  std::multiset<std::string> request_readers_;  ///< prefixes of matched request readers
  std::multiset<std::string> reply_writers_;    ///< prefixes of matched reply writers
  std::multiset<std::string> event_writers_;    ///< prefixes of matched event writers
  std::multiset<std::string> group_request_readers_;
  std::multiset<std::string> group_reply_writers_;
  std::multiset<std::string> admin_request_readers_;
  /// A participant whose owner writer matched ours is ready only once it is
  /// alive: otherwise a death just after we became ready would go unseen.
  std::multiset<std::string> owner_writers_;
};

}  // namespace dh3::detail
