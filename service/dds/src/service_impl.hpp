#pragma once
// Service::Impl (service.cpp): the composition of the service's DDS side. It
// owns the participant and its endpoints, the buses' schedulers, and wires
// the parts that do the work: StatusPublisher (statuses, events, service
// info), ReplyChannel (replies and their gates), RequestHandler and
// GroupCommands (requests), ClientShare (each client's requests in flight),
// LeaseTable and the ExpiryTimer (leases), LeasePublisher (the leases, for a
// standby), ParticipantNames (how lease holders are shown).
//
// Locks. dispatch_mutex_ (here) is outermost: one request or group request at
// a time, and stop() takes it to know none is in flight. Under it a request
// may take a bus's status mutex (StatusPublisher), and under that the status
// write and info mutexes. The scans mutex (RequestHandler), each group's
// mutex (GroupCommands), the lease table's, the client share's and the reply gates' are leaves,
// never held while a sample is written; the timer's mutex is held only around
// the lease table's and gates' next_expiry(). Fast DDS writes happen under
// dispatch_mutex_ (an answer given at once) and under a bus's status mutex
// (statuses, events, info), which the request and participant listener
// callbacks also take: as before the parts were split out, and no writer's
// own listener (ReplyChannel's matches) takes either. After a takeover each
// request drain's mutex is taken under dispatch_mutex_ once (serve_kept) and
// by Fast DDS's threads under nothing of ours: it is a leaf too.

#include <spdlog/spdlog.h>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "conversions.hpp"
#include "dh3/contract/dh3PubSubTypes.h"
#include "dh3/contract/listened_participant.hpp"
#include "dh3/contract/participant.hpp"
#include "dh3/contract/participant_setup.hpp"
#include "dh3/contract/qos.hpp"
#include "dh3/dds/service.hpp"
#include "dh3/dds/standby_presence.hpp"
#include "expiry_timer.hpp"
#include "group_commands.hpp"
#include "hand_directory.hpp"
#include "lease_publisher.hpp"
#include "lease_table.hpp"
#include "owner_beacon.hpp"
#include "participant_names.hpp"
#include "reply_channel.hpp"
#include "request_drain.hpp"
#include "request_handler.hpp"
#include "service_endpoints.hpp"
#include "status_publisher.hpp"

namespace dh3::dds {
namespace fdds = eprosima::fastdds::dds;

class Service::Impl {
 public:
  Impl(ServiceOptions options, const Clock& clock);
  ~Impl();
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  /// `standby`: the participant, owner beacon, endpoints and request drains
  /// to serve on (a takeover); empty: made here.
  Result<void, std::string> init(std::vector<BusSetup> setups,
                                 StandbyPresence::Handover standby = {});
  Result<void, std::string> start();
  void stop();
  [[nodiscard]] Service::Refusals refusals() const {
    return {share_.refused(), rate_.refused(), replies_.dropped_replies()};
  }
  [[nodiscard]] std::vector<hand::BusMetrics> metrics() const {
    std::vector<hand::BusMetrics> out;
    for (const auto& scheduler : schedulers_) out.push_back(scheduler->metrics());
    return out;
  }

 private:
  /// Forwards one bus's scheduler callbacks to the StatusPublisher, tagged with the bus.
  class BusObserver final : public hand::HandObserver {
   public:
    BusObserver(StatusPublisher& statuses, std::uint16_t bus) : statuses_(statuses), bus_(bus) {}
    void on_state(const hand::HandState& state) override { statuses_.on_state(bus_, state); }
    // The same values, read again: republished, once per status_refresh, so
    // that read_at_ns shows it.
    void on_fresh(const hand::HandState& state) override { statuses_.on_fresh(bus_, state); }
    void on_event(const hand::HandEvent& event) override { statuses_.on_event(bus_, event); }
    void on_link(bus::LinkState state) override { statuses_.on_link(bus_, state); }
    void on_batch_end(std::uint8_t can_id) override { statuses_.send_held(bus_, can_id); }

   private:
    StatusPublisher& statuses_;
    std::uint16_t bus_;
  };

  class RequestListener final : public fdds::DataReaderListener {
   public:
    RequestListener(Impl& impl, RequestTopic topic) : impl_(impl), topic_(topic) {}
    void on_data_available(fdds::DataReader* reader) override {
      impl_.on_requests(*reader, topic_);
    }
    // Only logged: which clients' requests can reach us (a client whose
    // writer never matches here gets no reply, whatever it sees on its side).
    void on_subscription_matched(fdds::DataReader* /*reader*/,
                                 const fdds::SubscriptionMatchedStatus& status) override {
      if (!spdlog::should_log(spdlog::level::debug)) return;
      spdlog::debug(
          "{}request writer of {} {} ({} matched)", topic_ == RequestTopic::admin ? "admin " : "",
          contract::client_id_for(status.last_publication_handle),
          status.current_count_change > 0 ? "matched" : "unmatched", status.current_count);
    }

   private:
    Impl& impl_;
    RequestTopic topic_;
  };

  class GroupRequestListener final : public fdds::DataReaderListener {
   public:
    explicit GroupRequestListener(Impl& impl) : impl_(impl) {}
    void on_data_available(fdds::DataReader* reader) override { impl_.on_group_requests(*reader); }

   private:
    Impl& impl_;
  };

  // Requests (DDS listener threads), under dispatch_mutex_.
  void on_requests(fdds::DataReader& reader, RequestTopic topic);
  /// Serves intake_ (taken from `topic` by `callers`), one client at a time.
  void serve_intake(std::vector<Caller>& callers, RequestTopic topic);
  /// What a standby's drains kept since its claim turned active, served
  /// before anything that comes after; from then on they forward to the
  /// listeners here.
  void serve_kept();
  void on_group_requests(fdds::DataReader& reader);
  /// A request sample is this service's to serve: valid, the name is this
  /// service's, and the request is not for another incarnation of it.
  [[nodiscard]] bool serves(const fdds::SampleInfo& info);
  /// Who wrote a request sample: its participant, never the request's client_id.
  [[nodiscard]] Caller caller_of(const fdds::SampleInfo& info) const;
  /// What the participant listener does with each participant that joins or leaves.
  contract::PeerDiscoveryListener::Callbacks peer_callbacks();
  /// A client that leaves the domain loses its held replies and its leases at once.
  void on_participant_left(const std::string& participant_id, bool dropped);
  /// The timer's job: held replies past their limit, then expired leases.
  void sweep_expired();

  // Set-up: each step names the entity it could not create.
  /// The owner endpoints, then the claim on the name (owner_beacon.hpp); a
  /// standby's beacon claims at once.
  Result<void, std::string> claim_name(bool standby);
  /// The writers, or those a standby made given their listeners.
  Result<void, std::string> create_writers();
  /// The lease writer, for the standby; without it (DDS Security
  /// permissions that predate it) the service serves, and says so.
  void create_lease_writer();
  /// The leases of the primary a standby took over from, by bus name.
  void load_leases(const std::vector<HandedLease>& handed);
  /// The request readers, or those a standby made given their listeners
  /// and the requests they kept served. A service whose DDS Security
  /// permissions predate the admin or group endpoints refuses those
  /// commands (and says so).
  Result<void, std::string> create_readers();
  [[nodiscard]] std::string cannot_create(const std::string& what) const;
  void destroy_dds();

  ServiceOptions options_;
  const Clock& clock_;
  HandDirectory directory_;
  LeaseTable leases_;
  ParticipantNames names_;
  LeasePublisher lease_share_{options_.name, leases_, directory_};  ///< for the standby
  Schedulers schedulers_;  ///< by bus index; fixed after init()
  std::vector<std::unique_ptr<BusObserver>> observers_;
  ReplyChannel replies_{clock_, options_.test_seam_tracer, [this] { timer_.wake(); }};
  StatusPublisher statuses_{options_, clock_, leases_, directory_};
  ExpiryTimer timer_;
  ClientShare share_;  ///< before requests_: the tickets in its completions point here
  ClientRate rate_{clock_, options_.client_rate_limit};
  RequestHandler requests_{
      {options_, directory_, leases_, schedulers_, statuses_, replies_, timer_, share_}};
  GroupCommands groups_{
      {options_, clock_, directory_, leases_, schedulers_, replies_, share_, rate_}};

  RequestListener request_listener_{*this, RequestTopic::commands};
  RequestListener admin_request_listener_{*this, RequestTopic::admin};
  GroupRequestListener group_request_listener_{*this};
  /// The participant, its topics, publisher and subscriber (not joined until
  /// init() has made them); the writers and readers below are made on them and
  /// deleted with them, before the listeners above.
  /// A standby's, after its takeover: the request readers' listeners, which
  /// forward to those above. Before participant_: it outlives the readers.
  std::unique_ptr<RequestDrains> drains_;
  contract::ListenedParticipant participant_{peer_callbacks()};
  /// Real time, whatever clock_ is: it waits on DDS discovery and liveliness.
  std::unique_ptr<OwnerBeacon> owner_ = std::make_unique<OwnerBeacon>(SystemClock::instance());
  ServiceEndpoints endpoints_;

  std::mutex dispatch_mutex_;
  bool stopping_ = false;  ///< under dispatch_mutex_
  /// Requests taken from the reader and served together, at most
  /// kIntakeBatch: a few hundred bytes each, and enough that a flood taken
  /// ahead of another client's request still shares the batch with it.
  std::vector<msg::CommandRequest> intake_;  ///< reused by the listener thread
  static constexpr std::size_t kIntakeBatch = 64;
  msg::GroupRequest group_request_;  ///< reused by the group listener thread

  bool started_ = false;
  bool stopped_ = false;
};

}  // namespace dh3::dds
