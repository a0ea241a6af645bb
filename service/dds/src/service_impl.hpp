#pragma once
// Service::Impl, shared by the files that implement it: service.cpp (set-up,
// start, stop, tear-down), service_publishing.cpp (statuses, events, service
// info), service_requests.cpp (requests and their replies) and
// service_leases.cpp (control leases and their timer).

#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <condition_variable>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <mutex>
#include <thread>

#include "dh3/dds/conversions.hpp"
#include "dh3/dds/group_validation.hpp"
#include "dh3/dds/hand_directory.hpp"
#include "dh3/dds/lease_table.hpp"
#include "dh3/dds/reply_gate.hpp"
#include "dh3/dds/request_validation.hpp"
#include "dh3/dds/service.hpp"
#include "dh3_idl/dh3PubSubTypes.h"
#include "dh3_participant_setup.hpp"
#include "dh3_qos.hpp"

namespace dh3::dds {
namespace fdds = eprosima::fastdds::dds;

/// What a reply echoes from its request.
struct ReplyHeader {
  std::string client_id;
  std::uint64_t request_seq = 0;
  msg::HandAddress hand;
  msg::CommandType command = msg::INITIALIZE;
};

inline msg::CommandReply make_reply(const ReplyHeader& header, msg::ResultCode code,
                                    std::string message = {}) {
  msg::CommandReply reply;
  reply.client_id(header.client_id);
  reply.request_seq(header.request_seq);
  reply.hand(header.hand);
  reply.command(header.command);
  reply.code(code);
  reply.message(std::move(message));
  return reply;
}

inline std::string hand_text(std::string_view bus, std::uint8_t can_id) {
  return "hand " + std::to_string(can_id) + " on bus '" + std::string(bus) + "'";
}

class Service::Impl {
 public:
  Impl(ServiceOptions options, const Clock& clock)
      : options_(std::move(options)),
        clock_(clock),
        leases_(clock),
        reply_gate_(clock, kReplyHoldLimit),
        group_reply_gate_(clock, kReplyHoldLimit) {}
  ~Impl() {
    stop();
    // Schedulers go first: a scheduler that never ran may still report its
    // hands offline while it shuts down, and that needs the writers.
    for (auto& bus : buses_) bus->scheduler.reset();
    destroy_dds();
  }

  Result<void, std::string> init(std::vector<BusSetup> setups);
  Result<void, std::string> start();
  void stop();
  [[nodiscard]] std::vector<hand::BusMetrics> metrics() const {
    std::vector<hand::BusMetrics> out;
    for (const auto& bus : buses_) out.push_back(bus->scheduler->metrics());
    return out;
  }

 private:
  /// Forwards one bus's scheduler callbacks, tagged with the bus.
  class BusObserver final : public hand::HandObserver {
   public:
    BusObserver(Impl& impl, std::uint16_t bus) : impl_(impl), bus_(bus) {}
    void on_state(const hand::HandState& state) override { impl_.on_state(bus_, state); }
    // The same values, read again: republished, once per status_refresh, so
    // that read_at_ns shows it.
    void on_fresh(const hand::HandState& state) override { impl_.on_fresh(bus_, state); }
    void on_event(const hand::HandEvent& event) override { impl_.on_event(bus_, event); }
    void on_link(bus::LinkState state) override { impl_.on_link(bus_, state); }
    void on_batch_end(std::uint8_t can_id) override { impl_.send_held_status(bus_, can_id); }

   private:
    Impl& impl_;
    std::uint16_t bus_;
  };

  class RequestListener final : public fdds::DataReaderListener {
   public:
    explicit RequestListener(Impl& impl) : impl_(impl) {}
    void on_data_available(fdds::DataReader* reader) override { impl_.on_requests(*reader); }

   private:
    Impl& impl_;
  };

  class GroupRequestListener final : public fdds::DataReaderListener {
   public:
    explicit GroupRequestListener(Impl& impl) : impl_(impl) {}
    void on_data_available(fdds::DataReader* reader) override { impl_.on_group_requests(*reader); }

   private:
    Impl& impl_;
  };

  /// A reply writer's matches: a client's held replies go out when its
  /// reader matches (ReplyGate). Fast DDS calls it without the writer's locks.
  class ReplyWriterListener final : public fdds::DataWriterListener {
   public:
    using OnReader = void (Impl::*)(const std::string& client_id, bool matched);
    ReplyWriterListener(Impl& impl, OnReader on_reader) : impl_(impl), on_reader_(on_reader) {}
    void on_publication_matched(fdds::DataWriter* /*writer*/,
                                const fdds::PublicationMatchedStatus& status) override {
      eprosima::fastrtps::rtps::GUID_t reader;
      eprosima::fastrtps::rtps::iHandle2GUID(reader, status.last_subscription_handle);
      (impl_.*on_reader_)(contract::client_id_for(reader.guidPrefix),
                          status.current_count_change > 0);
    }

   private:
    Impl& impl_;
    OnReader on_reader_;
  };

  class ParticipantListener final : public fdds::DomainParticipantListener {
   public:
    explicit ParticipantListener(Impl& impl) : impl_(impl) {}
    void on_participant_discovery(
        fdds::DomainParticipant* /*participant*/,
        eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) override {
      using Status = eprosima::fastrtps::rtps::ParticipantDiscoveryInfo;
      if (info.status == Status::DISCOVERED_PARTICIPANT) {
        const std::string client_id = contract::client_id_for(info.info.m_guid.guidPrefix);
        impl_.reply_gate_.participant_joined(client_id);
        impl_.group_reply_gate_.participant_joined(client_id);
      } else if (info.status == Status::REMOVED_PARTICIPANT ||
                 info.status == Status::DROPPED_PARTICIPANT) {
        impl_.on_participant_left(contract::client_id_for(info.info.m_guid.guidPrefix),
                                  info.status == Status::DROPPED_PARTICIPANT);
      }
    }

   private:
    Impl& impl_;
  };

  /// What only the DDS side knows of a hand: its status samples. Its state is
  /// the driver's; each sample is filled from the state the bus reports.
  ///
  /// A sample is prepared (update_seq, lease holder, time) and then sent. A
  /// state the bus loop reports is held, prepared but not sent, until the end
  /// of its batch (HandObserver::on_batch_end): the commands that ended with
  /// it are answered first, their replies carrying the held sample
  /// (CommandReply.status), so a state-changing command's reply does not wait
  /// for a status sample to be written. An event of the hand sends a held
  /// sample first: statuses still go out before the events they explain.
  struct HandSlot {
    std::uint64_t update_seq = 0;
    bool announced = false;  ///< the service info lists it
    bool written = false;    ///< `sample` was filled from a reported state
    bool held = false;       ///< `sample` is prepared and not sent yet
    TimePoint sent_at{};     ///< when a sample of this hand was last written
    msg::HandStatus sample;  ///< the last sample, reused for every sample of this hand
  };

  struct BusRuntime {
    std::string name;
    std::string spec;
    std::unique_ptr<BusObserver> observer;
    std::unique_ptr<hand::BusScheduler> scheduler;
    std::atomic<bool> link_up{false};
    /// Orders the status samples of this bus's hands: the bus thread and lease
    /// changes both publish, and the last sample written must be the newest.
    std::mutex status_mutex;
    std::array<std::unique_ptr<HandSlot>, 256> hands{};
    msg::HandEvent event_sample;  ///< reused; under status_mutex
  };

  struct PendingScan {
    ReplyHeader header;
    std::atomic<bool> answered{false};
  };

  // Scheduler callbacks (bus threads).
  void on_state(std::uint16_t bus, const hand::HandState& state);
  /// The same values read again: published if the last sample is older than
  /// options_.status_refresh.
  void on_fresh(std::uint16_t bus, const hand::HandState& state);
  void on_event(std::uint16_t bus, const hand::HandEvent& event);
  void on_link(std::uint16_t bus, bus::LinkState state);

  // Requests (DDS listener thread).
  void on_requests(fdds::DataReader& reader);
  void handle_request(msg::CommandRequest& request);
  void submit_command(const ValidRequest& valid, ReplyHeader header);
  void start_scan(const ValidRequest& valid, ReplyHeader header);
  void handle_lease(const ValidRequest& valid, const ReplyHeader& header);
  void finish_scan(const std::shared_ptr<PendingScan>& scan, msg::ResultCode code,
                   const std::vector<std::uint8_t>& found, std::string message);
  /// Writes the reply, or leaves it with the reply gate until the client's
  /// reply reader has matched (`reply` is then moved from).
  void write_reply(msg::CommandReply& reply);
  /// Writes the reply now, past the gate.
  void publish_reply(msg::CommandReply& reply);
  /// A reader of `client_id`'s participant matched (or left) the reply writer.
  void on_reply_reader(const std::string& client_id, bool matched);
  /// Copies the hand's last prepared status sample into the reply (sent or
  /// held); leaves the reply's empty (update_seq 0) if the hand has none.
  void attach_status(msg::CommandReply& reply, std::uint16_t bus, std::uint8_t can_id);

  // Group requests (DDS listener thread; service_groups.cpp).
  struct PendingGroup;
  void on_group_requests(fdds::DataReader& reader);
  void handle_group(msg::GroupRequest& request);
  /// Answers a group that failed its checks: nothing was sent to any hand.
  void refuse_group(msg::GroupReply& reply, const GroupRefusal& refusal);
  void submit_group(const std::vector<ValidRequest>& members, msg::GroupReply reply,
                    Duration timeout);
  [[nodiscard]] MemberFacts member_facts(std::uint16_t bus, std::uint8_t can_id,
                                         const std::string& client_id) const;
  /// Writes the group reply, or leaves it with the group reply gate until
  /// the client's group reply reader has matched (`reply` is then moved from).
  void write_group_reply(msg::GroupReply& reply);
  /// Writes the group reply now, past the gate.
  void publish_group_reply(msg::GroupReply& reply);
  /// A reader of `client_id`'s participant matched (or left) the group reply writer.
  void on_group_reply_reader(const std::string& client_id, bool matched);
  /// The group endpoints; a service whose DDS Security permissions predate
  /// them runs without group commands (and says so).
  void create_group_endpoints();

  // Leases.
  void on_participant_left(const std::string& participant_id, bool dropped);
  void lease_timer_loop();
  void wake_lease_timer();

  // Publishing.
  HandSlot& slot_locked(BusRuntime& bus, std::uint8_t can_id);
  /// `hold`: prepare the sample and leave it for send_held_status().
  void on_state_locked(std::uint16_t bus, const hand::HandState& state, bool hold);
  /// Gives the slot's sample its lease holder, next update_seq and time.
  void prepare_status_locked(std::uint16_t bus, std::uint8_t can_id, HandSlot& slot);
  void send_status_locked(std::uint16_t bus, std::uint8_t can_id, HandSlot& slot);
  /// prepare_status_locked() and send_status_locked().
  void write_status_locked(std::uint16_t bus, std::uint8_t can_id, HandSlot& slot);
  /// Sends the hand's held sample, if any (the end of a batch, or of a lease change).
  void send_held_status(std::uint16_t bus, std::uint8_t can_id);
  /// A hand-layer (steady) time on the wall clock, ns since the epoch; 0 for "never".
  [[nodiscard]] std::uint64_t wall_clock_ns_of(TimePoint time) const;
  void republish_status(HandKey hand);
  /// A new sample of the hand (its lease holder changed), held: copied into
  /// `reply` for the reply to go first; send_held_status() sends it after.
  void hold_republished_status(HandKey hand, msg::CommandReply& reply);
  void publish_info();

  // Set-up: each step names the entity it could not create.
  Result<void, std::string> create_writers();
  Result<void, std::string> create_request_reader();
  [[nodiscard]] std::string cannot_create(const std::string& what) const;

  void destroy_dds();

  /// How long a reply waits for its client's reply reader to match before it
  /// is written anyway: as long as a client waits for a reply at most.
  static constexpr Duration kReplyHoldLimit =
      std::chrono::milliseconds(limits::REQUEST_TIMEOUT_MAX_MS);

  ServiceOptions options_;
  const Clock& clock_;
  HandDirectory directory_;
  LeaseTable leases_;
  ReplyGate<msg::CommandReply> reply_gate_;
  ReplyGate<msg::GroupReply> group_reply_gate_;
  std::vector<std::unique_ptr<BusRuntime>> buses_;
  std::uint64_t started_ns_ = wall_clock_ns();
  std::atomic<std::uint64_t> event_seq_{0};

  ParticipantListener participant_listener_{*this};
  RequestListener request_listener_{*this};
  ReplyWriterListener reply_writer_listener_{*this, &Impl::on_reply_reader};
  ReplyWriterListener group_reply_writer_listener_{*this, &Impl::on_group_reply_reader};
  GroupRequestListener group_request_listener_{*this};
  /// The participant, its topics, publisher and subscriber (null until init()
  /// has made them); the writers and the reader below are made on them and
  /// deleted with them.
  std::unique_ptr<contract::Participant> participant_;
  fdds::Topic* status_topic_ = nullptr;
  fdds::Topic* event_topic_ = nullptr;
  fdds::Topic* info_topic_ = nullptr;
  fdds::Topic* request_topic_ = nullptr;
  fdds::Topic* reply_topic_ = nullptr;
  fdds::DataWriter* status_writer_ = nullptr;
  /// Status is keyed, and the generated type computes a sample's key in one
  /// buffer of its own: two buses' threads writing at once would mix up their
  /// hands' instances (ThreadSanitizer found it). Bus status mutexes only
  /// order one bus's samples, so writes to this writer take this as well.
  std::mutex status_write_mutex_;
  fdds::DataWriter* event_writer_ = nullptr;
  fdds::DataWriter* info_writer_ = nullptr;
  fdds::DataWriter* reply_writer_ = nullptr;
  fdds::DataReader* request_reader_ = nullptr;
  fdds::DataReader* group_request_reader_ = nullptr;
  fdds::DataWriter* group_reply_writer_ = nullptr;

  std::mutex info_mutex_;

  /// Held while requests are dispatched; stop() takes it to know none is in flight.
  std::mutex dispatch_mutex_;
  bool stopping_ = false;        ///< under dispatch_mutex_
  msg::CommandRequest request_;  ///< reused by the listener thread
  msg::GroupRequest group_request_;  ///< reused by the group listener thread

  std::mutex scans_mutex_;
  std::vector<std::shared_ptr<PendingScan>> scans_;

  std::mutex lease_timer_mutex_;
  std::condition_variable lease_timer_cv_;
  std::uint64_t lease_timer_generation_ = 0;  ///< under lease_timer_mutex_
  bool lease_timer_stop_ = false;             ///< under lease_timer_mutex_
  std::thread lease_timer_;

  bool started_ = false;
  bool stopped_ = false;
};

}  // namespace dh3::dds
