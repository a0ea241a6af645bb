// dh3::dds::Service: set-up, start, stop and tear-down of the service's DDS
// side. Its other jobs: service_publishing.cpp, service_requests.cpp,
// service_leases.cpp (all on Service::Impl, service_impl.hpp).

#include "service_impl.hpp"

namespace dh3::dds {
using contract::TopicRole;
using eprosima::fastrtps::types::ReturnCode_t;

// ---------------------------------------------------------------------------
// Set-up and tear-down

Result<void, std::string> Service::Impl::init(std::vector<BusSetup> setups) {
  contract::ParticipantOptions participant = options_.participant;
  participant.name = "dh3-service " + options_.name;
  participant.cell = options_.name;
  contract::SetupReport report;
  auto made = contract::Participant::create(participant, report, &participant_listener_);
  // Before the outcome: an ignored option may explain a failure.
  for (const auto& warning : report.warnings) spdlog::warn("{}", warning);
  for (const auto& note : report.notes) spdlog::info("{}", note);
  if (!made) return fail(std::move(made).error());
  participant_ = std::move(made).value();
  if (const auto& cell = participant_->published_cell()) {
    spdlog::info("publishing in the default partition and in '{}', for followers of the cell",
                 *cell);
  }
  if (!options_.participant.security_dir.empty()) {
    spdlog::info("DDS Security on: identity '{}' in '{}'", options_.participant.security_identity,
                 options_.participant.security_dir);
  }
  if (auto created = create_writers(); !created) return created;

  for (auto& setup : setups) {
    const auto index = static_cast<std::uint16_t>(buses_.size());
    auto runtime = std::make_unique<BusRuntime>();
    runtime->name = setup.name;
    runtime->spec = setup.bus->spec();
    runtime->observer = std::make_unique<BusObserver>(*this, index);
    // Configured hands are in the service info from the start: not news (on_state).
    for (const auto& hand : setup.hands) slot_locked(*runtime, hand.can_id).announced = true;
    // In the list before the scheduler exists: it may report (states, never
    // events) from its constructor.
    BusRuntime& added = *buses_.emplace_back(std::move(runtime));
    setup.scheduler.allow_admin = options_.allow_admin;
    added.scheduler = std::make_unique<hand::BusScheduler>(
        setup.name, std::move(setup.bus), setup.hands, setup.scheduler, clock_, *added.observer);
    added.link_up = added.scheduler->link_state() == bus::LinkState::up;
    directory_.add_bus(setup.name, added.scheduler->roster());
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
  const auto writer = [this](fdds::DataWriter*& out, fdds::Topic* topic, TopicRole role,
                             fdds::DataWriterListener* listener =
                                 nullptr) -> Result<void, std::string> {
    out = participant_->publisher().create_datawriter(
        topic, contract::writer_qos(role), listener,
        listener ? fdds::StatusMask::publication_matched() : fdds::StatusMask::none());
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
  return writer(reply_writer_, reply_topic_, TopicRole::reply, &reply_writer_listener_);
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
    for (const hand::HandState& state : bus.scheduler->state()) {
      std::lock_guard lock(bus.status_mutex);
      if (slot_locked(bus, state.can_id).update_seq == 0) {
        on_state_locked(static_cast<std::uint16_t>(i), state, false);
      }
    }
  }
  for (auto& bus : buses_) bus->scheduler->start();
  lease_timer_ = std::thread([this] { lease_timer_loop(); });
  // Last: requests are only taken once everything they need runs.
  if (auto created = create_request_reader(); !created) return created;
  create_group_endpoints();
  spdlog::info("service '{}' on DDS domain {}: {} bus(es), admin commands {}", options_.name,
               options_.participant.domain, buses_.size(),
               options_.allow_admin ? "allowed" : "refused");
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
    for (std::size_t id = 0; id < bus.hands.size(); ++id) {
      HandSlot* slot = bus.hands[id].get();
      if (slot && slot->written && slot->sample.online()) {
        slot->sample.online(false);
        write_status_locked(static_cast<std::uint16_t>(i), static_cast<std::uint8_t>(id), *slot);
      }
    }
  }
  // Replies still waiting for their reader go out now, to the writer's history.
  for (auto& reply : reply_gate_.take_all()) publish_reply(reply);
  for (auto& reply : group_reply_gate_.take_all()) publish_group_reply(reply);
  // Subscribers get the offline samples and last replies before we leave.
  const auto deadline = SteadyClock::now() + options_.shutdown_ack_timeout;
  for (fdds::DataWriter* writer :
       {status_writer_, reply_writer_, event_writer_, group_reply_writer_}) {
    if (writer == nullptr) continue;  // group commands off (see create_group_endpoints)
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
  if (group_request_reader_ != nullptr) group_request_reader_->set_listener(nullptr);
  group_request_reader_ = nullptr;
  group_reply_writer_ = nullptr;
  if (reply_writer_ != nullptr) reply_writer_->set_listener(nullptr);
  status_writer_ = event_writer_ = info_writer_ = reply_writer_ = nullptr;
  request_reader_ = nullptr;
  participant_.reset();  // its listener first, then everything it contains
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
