#include "dds/service.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <condition_variable>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <mutex>
#include <thread>

#include "dds/conversions.hpp"
#include "dds/hand_directory.hpp"
#include "dds/lease_table.hpp"
#include "dds/request_validation.hpp"
#include "dh3_idl/dh3PubSubTypes.h"
#include "dh3_participant_setup.hpp"
#include "dh3_qos.hpp"

namespace dh3::dds {
namespace fdds = eprosima::fastdds::dds;
using contract::TopicRole;
using eprosima::fastrtps::types::ReturnCode_t;

namespace {

/// What a reply echoes from its request.
struct ReplyHeader {
  std::string client_id;
  std::uint64_t request_seq = 0;
  msg::HandAddress hand;
  msg::CommandType command = msg::INITIALIZE;
};

msg::CommandReply make_reply(const ReplyHeader& header, msg::ResultCode code,
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

std::string hand_text(std::string_view bus, std::uint8_t can_id) {
  return "hand " + std::to_string(can_id) + " on bus '" + std::string(bus) + "'";
}

}  // namespace

class Service::Impl {
 public:
  Impl(ServiceOptions options, const Clock& clock)
      : options_(std::move(options)), clock_(clock), leases_(clock) {}
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
    void on_event(const hand::HandEvent& event) override { impl_.on_event(bus_, event); }
    void on_link(bus::LinkState state) override { impl_.on_link(bus_, state); }

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

  class ParticipantListener final : public fdds::DomainParticipantListener {
   public:
    explicit ParticipantListener(Impl& impl) : impl_(impl) {}
    void on_participant_discovery(
        fdds::DomainParticipant* /*participant*/,
        eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) override {
      using Status = eprosima::fastrtps::rtps::ParticipantDiscoveryInfo;
      if (info.status == Status::REMOVED_PARTICIPANT ||
          info.status == Status::DROPPED_PARTICIPANT) {
        impl_.on_participant_left(contract::client_id_for(info.info.m_guid.guidPrefix),
                                  info.status == Status::DROPPED_PARTICIPANT);
      }
    }

   private:
    Impl& impl_;
  };

  struct HandSlot {
    hand::HandState state;
    std::uint64_t update_seq = 0;
    msg::HandStatus sample;  ///< reused for every sample of this hand
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
  void write_reply(msg::CommandReply& reply);

  // Leases.
  void on_participant_left(const std::string& participant_id, bool dropped);
  void lease_timer_loop();
  void wake_lease_timer();

  // Publishing.
  HandSlot& slot_locked(BusRuntime& bus, std::uint8_t can_id);
  void publish_status_locked(std::uint16_t bus, HandSlot& slot);
  void republish_status(HandKey hand);
  void publish_info();

  // Set-up: each step names the entity it could not create.
  Result<void, std::string> create_writers();
  Result<void, std::string> create_request_reader();
  [[nodiscard]] std::string cannot_create(const std::string& what) const;

  void destroy_dds();

  ServiceOptions options_;
  const Clock& clock_;
  HandDirectory directory_;
  LeaseTable leases_;
  std::vector<std::unique_ptr<BusRuntime>> buses_;
  std::uint64_t started_ns_ = wall_clock_ns();
  std::atomic<std::uint64_t> event_seq_{0};

  ParticipantListener participant_listener_{*this};
  RequestListener request_listener_{*this};
  /// The participant, its topics, publisher and subscriber; the writers and
  /// the reader below are made on them and deleted with them.
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

  std::mutex info_mutex_;

  /// Held while requests are dispatched; stop() takes it to know none is in flight.
  std::mutex dispatch_mutex_;
  bool stopping_ = false;        ///< under dispatch_mutex_
  msg::CommandRequest request_;  ///< reused by the listener thread

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

// ---------------------------------------------------------------------------
// Set-up and tear-down

Result<void, std::string> Service::Impl::init(std::vector<BusSetup> setups) {
  contract::ParticipantOptions participant = options_.participant;
  participant.name = "dh3-service " + options_.name;
  participant_ = std::make_unique<contract::Participant>(participant, &participant_listener_);
  for (const auto& warning : participant_->warnings()) spdlog::warn("{}", warning);
  for (const auto& note : participant_->notes()) spdlog::info("{}", note);
  if (!participant_->ok()) return fail(participant_->error());
  if (!options_.participant.security_dir.empty()) {
    spdlog::info("DDS Security on: identity '{}' in '{}'", options_.participant.security_identity,
                 options_.participant.security_dir);
  }
  if (auto created = create_writers(); !created) return created;

  for (auto& setup : setups) {
    std::vector<HandDirectory::Hand> hands;
    for (const auto& hand : setup.hands) hands.push_back({hand.can_id, hand.name});
    const std::uint16_t index = directory_.add_bus(setup.name, hands);
    auto runtime = std::make_unique<BusRuntime>();
    runtime->name = setup.name;
    runtime->spec = setup.bus->spec();
    runtime->observer = std::make_unique<BusObserver>(*this, index);
    for (const auto& hand : setup.hands) {
      HandSlot& slot = slot_locked(*runtime, hand.can_id);
      slot.state.name = hand.name;
    }
    // In the list before the scheduler exists: it may report from its constructor.
    BusRuntime& added = *buses_.emplace_back(std::move(runtime));
    setup.scheduler.allow_admin = options_.allow_admin;
    added.scheduler = std::make_unique<hand::BusScheduler>(
        setup.name, std::move(setup.bus), setup.hands, setup.scheduler, clock_, *added.observer);
    added.link_up = added.scheduler->link_state() == bus::LinkState::up;
  }
  return {};
}

std::string Service::Impl::cannot_create(const std::string& what) const {
  std::string message = "cannot create " + what;
  const auto& participant = options_.participant;
  if (!participant.security_dir.empty()) {
    return message + ": the DDS Security permissions of identity '" +
           participant.security_identity + "' in '" + participant.security_dir +
           "' must allow it (Fast DDS logs what it refused)";
  }
  if (participant_->security_from_profile()) {
    return message + ": the DDS Security permissions the XML profile names must allow it";
  }
  return message + " (Fast DDS logs why)";
}

Result<void, std::string> Service::Impl::create_writers() {
  const contract::Topics& topics = participant_->topics();
  status_topic_ = topics.status;
  event_topic_ = topics.event;
  info_topic_ = topics.info;
  request_topic_ = topics.request;
  reply_topic_ = topics.reply;
  const auto writer = [this](fdds::DataWriter*& out, fdds::Topic* topic,
                             TopicRole role) -> Result<void, std::string> {
    out = participant_->publisher().create_datawriter(topic, contract::writer_qos(role));
    if (out == nullptr) return fail(cannot_create("the writer of " + topic->get_name()));
    return {};
  };
  if (auto created = writer(status_writer_, status_topic_, TopicRole::hand_status); !created) {
    return created;
  }
  if (auto created = writer(event_writer_, event_topic_, TopicRole::hand_event); !created) {
    return created;
  }
  if (auto created = writer(info_writer_, info_topic_, TopicRole::service_info); !created) {
    return created;
  }
  return writer(reply_writer_, reply_topic_, TopicRole::reply);
}

Result<void, std::string> Service::Impl::create_request_reader() {
  // KEEP_ALL on our side (history is not part of matching): a burst of
  // requests from many clients is held back by reliable flow control instead of
  // overwriting requests not yet taken, which would then never be answered.
  auto request_qos = contract::reader_qos(TopicRole::request);
  request_qos.history().kind = fdds::KEEP_ALL_HISTORY_QOS;
  request_reader_ = participant_->subscriber().create_datareader(
      request_topic_, request_qos, &request_listener_, fdds::StatusMask::data_available());
  if (request_reader_ == nullptr) {
    // Without it the service would run and never answer a request.
    return fail(cannot_create("the reader of " + request_topic_->get_name()));
  }
  return {};
}

Result<void, std::string> Service::Impl::start() {
  if (started_) return {};
  started_ = true;
  publish_info();
  for (std::size_t i = 0; i < buses_.size(); ++i) {
    BusRuntime& bus = *buses_[i];
    std::lock_guard lock(bus.status_mutex);
    for (auto& slot : bus.hands) {
      if (slot && slot->update_seq == 0)
        publish_status_locked(static_cast<std::uint16_t>(i), *slot);
    }
  }
  for (auto& bus : buses_) bus->scheduler->start();
  lease_timer_ = std::thread([this] { lease_timer_loop(); });
  // Last: requests are only taken once everything they need runs.
  if (auto created = create_request_reader(); !created) return created;
  spdlog::info("service '{}' on DDS domain {}: {} bus(es), admin commands {}", options_.name,
               options_.participant.domain, buses_.size(), options_.allow_admin ? "allowed" : "refused");
  return {};
}

void Service::Impl::stop() {
  if (!started_ || stopped_) return;
  stopped_ = true;
  spdlog::info("service '{}' stopping", options_.name);
  {
    std::lock_guard lock(dispatch_mutex_);
    stopping_ = true;  // requests from now on are answered CANCELLED
  }
  {
    std::lock_guard lock(lease_timer_mutex_);
    lease_timer_stop_ = true;
  }
  lease_timer_cv_.notify_all();
  if (lease_timer_.joinable()) lease_timer_.join();

  // The schedulers end their pending commands CANCELLED and report hands offline.
  for (auto& bus : buses_) bus->scheduler->stop();
  std::vector<std::shared_ptr<PendingScan>> scans;
  {
    std::lock_guard lock(scans_mutex_);
    scans.swap(scans_);
  }
  for (const auto& scan : scans) {
    finish_scan(scan, msg::CANCELLED, {}, "SCAN cancelled: the service is shutting down");
  }
  // Whatever the schedulers did not report, every hand goes out offline.
  for (std::size_t i = 0; i < buses_.size(); ++i) {
    BusRuntime& bus = *buses_[i];
    std::lock_guard lock(bus.status_mutex);
    for (auto& slot : bus.hands) {
      if (slot && slot->state.online) {
        slot->state.online = false;
        publish_status_locked(static_cast<std::uint16_t>(i), *slot);
      }
    }
  }
  // Subscribers get the offline samples and last replies before we leave.
  const auto deadline = SteadyClock::now() + options_.shutdown_ack_timeout;
  for (fdds::DataWriter* writer : {status_writer_, reply_writer_, event_writer_}) {
    const auto left = std::chrono::duration_cast<std::chrono::nanoseconds>(
        std::max(deadline - SteadyClock::now(), Duration::zero()));
    const eprosima::fastrtps::Duration_t wait(
        static_cast<std::int32_t>(left.count() / 1'000'000'000),
        static_cast<std::uint32_t>(left.count() % 1'000'000'000));
    if (writer->wait_for_acknowledgments(wait) != ReturnCode_t::RETCODE_OK) {
      spdlog::warn("not every subscriber acknowledged the last {} samples in time",
                   writer->get_topic()->get_name());
    }
  }
  spdlog::info("service '{}' stopped", options_.name);
}

void Service::Impl::destroy_dds() {
  if (participant_ == nullptr) return;
  if (request_reader_ != nullptr) request_reader_->set_listener(nullptr);
  status_writer_ = event_writer_ = info_writer_ = reply_writer_ = nullptr;
  request_reader_ = nullptr;
  participant_.reset();  // its listener first, then everything it contains
}

// ---------------------------------------------------------------------------
// Status, events, service info

Service::Impl::HandSlot& Service::Impl::slot_locked(BusRuntime& bus, std::uint8_t can_id) {
  auto& slot = bus.hands[can_id];
  if (!slot) {
    slot = std::make_unique<HandSlot>();
    slot->state.can_id = can_id;
  }
  return *slot;
}

void Service::Impl::publish_status_locked(std::uint16_t bus, HandSlot& slot) {
  const std::string holder = leases_.holder(HandKey{bus, slot.state.can_id});
  const StatusContext context{options_.name, buses_[bus]->name, holder, ++slot.update_seq,
                              wall_clock_ns()};
  fill_status(slot.sample, slot.state, context);
  if (status_writer_ == nullptr) return;  // DDS set-up failed or is gone
  std::lock_guard write_lock(status_write_mutex_);
  if (!status_writer_->write(&slot.sample)) {
    spdlog::warn("could not publish the status of {}",
                 hand_text(buses_[bus]->name, slot.state.can_id));
  }
}

void Service::Impl::republish_status(HandKey hand) {
  BusRuntime& bus = *buses_[hand.bus];
  std::lock_guard lock(bus.status_mutex);
  publish_status_locked(hand.bus, slot_locked(bus, hand.can_id));
}

void Service::Impl::on_state(std::uint16_t bus_index, const hand::HandState& state) {
  BusRuntime& bus = *buses_[bus_index];
  if (directory_.add_hand(bus_index, state.can_id)) {
    spdlog::debug("found {}", hand_text(bus.name, state.can_id));
    publish_info();
  }
  std::lock_guard lock(bus.status_mutex);
  HandSlot& slot = slot_locked(bus, state.can_id);
  const std::string name = slot.state.name;
  slot.state = state;
  if (slot.state.name.empty()) slot.state.name = name;
  publish_status_locked(bus_index, slot);
}

void Service::Impl::on_event(std::uint16_t bus_index, const hand::HandEvent& event) {
  BusRuntime& bus = *buses_[bus_index];
  // The hand layer logs events itself; this line only adds the service's view.
  spdlog::debug("event of {}: {}{}{}", hand_text(bus.name, event.can_id),
                hand::to_string(event.kind), event.message.empty() ? "" : ": ", event.message);
  if (event_writer_ == nullptr) return;
  std::lock_guard lock(bus.status_mutex);
  fill_event(bus.event_sample, event, options_.name, bus.name,
             directory_.hand_name(bus_index, event.can_id), ++event_seq_, wall_clock_ns());
  if (!event_writer_->write(&bus.event_sample)) {
    spdlog::warn("could not publish a {} event of {}", hand::to_string(event.kind),
                 hand_text(bus.name, event.can_id));
  }
}

void Service::Impl::on_link(std::uint16_t bus_index, bus::LinkState state) {
  const bool up = state == bus::LinkState::up;
  BusRuntime& bus = *buses_[bus_index];
  if (bus.link_up.exchange(up) == up) return;
  // The bus and hand layers log the link change; here it only goes to the service info.
  spdlog::debug("bus '{}' ({}) is {}: service info republished", bus.name, bus.spec,
                up ? "up" : "down");
  publish_info();
}

void Service::Impl::publish_info() {
  if (info_writer_ == nullptr) return;
  std::lock_guard lock(info_mutex_);
  msg::ServiceInfo info;
  info.service(options_.name);
  info.version(options_.version);
  info.host(options_.host);
  info.admin_allowed(options_.allow_admin);
  info.started_ns(started_ns_);
  for (std::size_t i = 0; i < buses_.size(); ++i) {
    msg::BusInfo bus;
    bus.name(buses_[i]->name);
    bus.spec(buses_[i]->spec);
    bus.link_up(buses_[i]->link_up.load());
    for (const auto& hand : directory_.hands(static_cast<std::uint16_t>(i))) {
      msg::HandInfo entry;
      entry.can_id(hand.can_id);
      entry.name(hand.name);
      bus.hands().push_back(std::move(entry));
    }
    info.buses().push_back(std::move(bus));
  }
  if (!info_writer_->write(&info)) {
    spdlog::warn("could not publish the service info");
  }
}

// ---------------------------------------------------------------------------
// Requests

void Service::Impl::on_requests(fdds::DataReader& reader) {
  std::lock_guard lock(dispatch_mutex_);
  fdds::SampleInfo info;
  while (reader.take_next_sample(&request_, &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data) continue;
    if (options_.tracer) options_.tracer(TracePoint::request_taken, request_.request_seq());
    handle_request(request_);
  }
}

void Service::Impl::handle_request(msg::CommandRequest& request) {
  const std::string& service = request.hand().service();
  if (!service.empty() && service != options_.name) return;  // another service's

  if (spdlog::should_log(spdlog::level::debug)) {
    spdlog::debug("request {}#{}: {} {}/{} value {}", request.client_id(), request.request_seq(),
                  command_name(request.command()), request.hand().bus(), request.hand().can_id(),
                  request.value());
  }
  if (stopping_) {
    const ReplyHeader header{request.client_id(), request.request_seq(), request.hand(),
                             request.command()};
    auto reply =
        make_reply(header, msg::CANCELLED,
                   command_name(header.command) + " cancelled: the service is shutting down");
    write_reply(reply);
    return;
  }
  auto valid = validate_request(request, directory_, options_.allow_admin);
  // The request object is reused for the next sample: its strings move into the reply.
  ReplyHeader header{std::move(request.client_id()), request.request_seq(),
                     std::move(request.hand()), request.command()};
  if (!valid) {
    spdlog::debug("request {}#{} refused: {}", header.client_id, header.request_seq,
                  valid.error().message);
    auto reply = make_reply(header, valid.error().code, std::move(valid.error().message));
    write_reply(reply);
    return;
  }
  switch (valid->action) {
    case RequestAction::hand_command:
      submit_command(*valid, std::move(header));
      break;
    case RequestAction::scan:
      start_scan(*valid, std::move(header));
      break;
    case RequestAction::acquire_lease:
    case RequestAction::renew_lease:
    case RequestAction::release_lease:
      handle_lease(*valid, header);
      break;
  }
}

void Service::Impl::submit_command(const ValidRequest& valid, ReplyHeader header) {
  if (valid.needs_lease) {
    const auto holder =
        valid.can_id == 0
            ? leases_.blocking_holder_on_bus(valid.bus, header.client_id)
            : leases_.blocking_holder(HandKey{valid.bus, valid.can_id}, header.client_id);
    if (holder) {
      auto reply =
          make_reply(header, msg::DENIED,
                     hand_text(header.hand.bus(), valid.can_id) + " is leased by client '" +
                         *holder + "'; only it may send " + command_name(header.command));
      reply.lease_holder(*holder);
      write_reply(reply);
      return;
    }
  }
  const std::uint8_t can_id = valid.can_id;
  buses_[valid.bus]->scheduler->submit(
      can_id, valid.command, [this, header = std::move(header)](const hand::CommandResult& result) {
        msg::CommandReply reply;
        if (result) {
          reply = make_reply(header, msg::OK);
          reply.value(result->value);
          reply.grasp(to_msg(result->grasp));
        } else {
          reply = make_reply(header, to_result_code(result.error()),
                             describe_failure(result.error(), header.command, header.hand.bus(),
                                              static_cast<std::uint8_t>(header.hand.can_id())));
        }
        write_reply(reply);
      });
}

void Service::Impl::start_scan(const ValidRequest& valid, ReplyHeader header) {
  auto scan = std::make_shared<PendingScan>();
  scan->header = std::move(header);
  {
    std::lock_guard lock(scans_mutex_);
    scans_.push_back(scan);
  }
  buses_[valid.bus]->scheduler->request_scan([this, scan](const std::vector<std::uint8_t>& found) {
    finish_scan(scan, msg::OK, found, {});
  });
}

void Service::Impl::finish_scan(const std::shared_ptr<PendingScan>& scan, msg::ResultCode code,
                                const std::vector<std::uint8_t>& found, std::string message) {
  if (scan->answered.exchange(true)) return;
  {
    std::lock_guard lock(scans_mutex_);
    std::erase(scans_, scan);
  }
  auto reply = make_reply(scan->header, code, std::move(message));
  reply.found_ids().assign(found.begin(), found.end());
  write_reply(reply);
}

void Service::Impl::handle_lease(const ValidRequest& valid, const ReplyHeader& header) {
  const HandKey hand{valid.bus, valid.can_id};
  LeaseAnswer answer;
  switch (valid.action) {
    case RequestAction::acquire_lease:
      answer = leases_.acquire(hand, header.client_id, valid.lease_ttl);
      break;
    case RequestAction::renew_lease:
      answer = leases_.renew(hand, header.client_id, valid.lease_ttl);
      break;
    default:
      answer = leases_.release(hand, header.client_id);
      break;
  }
  const std::string who = hand_text(header.hand.bus(), valid.can_id);
  msg::CommandReply reply;
  switch (answer.outcome) {
    case LeaseOutcome::granted:
      reply = make_reply(header, msg::OK);
      reply.value(static_cast<std::int32_t>(
          std::chrono::duration_cast<std::chrono::milliseconds>(valid.lease_ttl).count()));
      break;
    case LeaseOutcome::held_by_other:
      reply = make_reply(header, msg::DENIED,
                         who + " is leased by client '" + answer.holder + "'; " +
                             command_name(header.command) + " refused");
      break;
    case LeaseOutcome::not_held:
      reply = make_reply(header, msg::DENIED,
                         "client '" + header.client_id + "' holds no lease on " + who +
                             " (it expired or was released); use ACQUIRE_LEASE");
      break;
  }
  reply.lease_holder(answer.holder);
  if (answer.holder_changed) {
    spdlog::info("{}: lease {} by '{}'", who,
                 valid.action == RequestAction::release_lease ? "released" : "taken",
                 header.client_id);
    republish_status(hand);
  }
  write_reply(reply);
  if (valid.action != RequestAction::release_lease) wake_lease_timer();
}

void Service::Impl::write_reply(msg::CommandReply& reply) {
  if (reply.code() != msg::OK) {
    spdlog::debug("reply {}#{}: {} {}", reply.client_id(), reply.request_seq(),
                  result_code_name(reply.code()), reply.message());
  }
  if (reply_writer_ == nullptr) return;
  if (options_.tracer) options_.tracer(TracePoint::reply_writing, reply.request_seq());
  if (!reply_writer_->write(&reply)) {
    spdlog::warn("could not publish the reply to {}#{}", reply.client_id(), reply.request_seq());
  }
  if (options_.tracer) options_.tracer(TracePoint::reply_written, reply.request_seq());
}

// ---------------------------------------------------------------------------
// Leases

void Service::Impl::on_participant_left(const std::string& participant_id, bool dropped) {
  for (const auto& ended : leases_.drop_client(participant_id)) {
    spdlog::info("{}: lease of '{}' ended, its participant {} the domain",
                 hand_text(buses_[ended.hand.bus]->name, ended.hand.can_id), ended.holder,
                 dropped ? "dropped out of" : "left");
    republish_status(ended.hand);
  }
}

void Service::Impl::wake_lease_timer() {
  {
    std::lock_guard lock(lease_timer_mutex_);
    ++lease_timer_generation_;
  }
  lease_timer_cv_.notify_all();
}

void Service::Impl::lease_timer_loop() {
  std::unique_lock lock(lease_timer_mutex_);
  while (!lease_timer_stop_) {
    const std::uint64_t seen = lease_timer_generation_;
    const auto woken = [&] { return lease_timer_stop_ || lease_timer_generation_ != seen; };
    if (const auto next = leases_.next_expiry()) {
      // The lease table's clock is the steady clock in a running service.
      lease_timer_cv_.wait_until(lock, *next, woken);
    } else {
      lease_timer_cv_.wait(lock, woken);
    }
    if (lease_timer_stop_) break;
    lock.unlock();
    for (const auto& ended : leases_.expire()) {
      spdlog::info("{}: lease of '{}' expired",
                   hand_text(buses_[ended.hand.bus]->name, ended.hand.can_id), ended.holder);
      republish_status(ended.hand);
    }
    lock.lock();
  }
}

// ---------------------------------------------------------------------------

Service::Service(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Service::~Service() = default;

Result<std::unique_ptr<Service>, std::string> Service::create(ServiceOptions options,
                                                              std::vector<BusSetup> buses,
                                                              const Clock& clock) {
  auto impl = std::make_unique<Impl>(std::move(options), clock);
  if (auto ok = impl->init(std::move(buses)); !ok) return fail(ok.error());
  return std::unique_ptr<Service>(new Service(std::move(impl)));
}

Result<void, std::string> Service::start() {
  return impl_->start();
}
std::vector<hand::BusMetrics> Service::metrics() const {
  return impl_->metrics();
}
void Service::stop() {
  impl_->stop();
}

}  // namespace dh3::dds
