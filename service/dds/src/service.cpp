// dh3::dds::Service and its Impl: set-up, start, stop and tear-down of the
// service's DDS side, and the wiring of its parts (service_impl.hpp).

#include <algorithm>

#include "dh3/contract/request_address.hpp"
#include "lease_mirror.hpp"
#include "round_robin.hpp"
#include "service_impl.hpp"

namespace dh3::dds {
using contract::TopicRole;
using eprosima::fastrtps::types::ReturnCode_t;

// ---------------------------------------------------------------------------
// Set-up and tear-down

Service::Impl::Impl(ServiceOptions options, const Clock& clock)
    : options_(std::move(options)),
      clock_(clock),
      leases_(clock),
      timer_(
          [this] {
            auto next = leases_.next_expiry();
            if (const auto reply_due = replies_.next_expiry();
                reply_due && (!next || *reply_due < *next)) {
              next = reply_due;
            }
            return next;
          },
          [this] { sweep_expired(); }) {
  leases_.on_change([this](HandKey hand) { lease_share_.publish(hand); });
}

Service::Impl::~Impl() {
  stop();
  // Schedulers go first: a scheduler that never ran may still report its
  // hands offline while it shuts down, and that needs the writers.
  for (auto& scheduler : schedulers_) scheduler.reset();
  destroy_dds();
}

Result<void, std::string> Service::Impl::init(std::vector<BusSetup> setups,
                                              StandbyPresence::Handover standby) {
  const bool taking_over = standby.participant != nullptr;
  if (taking_over) {
    owner_ = std::move(standby.beacon);
    if (standby.endpoints) endpoints_ = *standby.endpoints;
    drains_ = std::move(standby.drains);
    // The clients it knew already are shown by their id until they change.
    participant_.adopt(std::move(standby.participant));
  } else {
    contract::ParticipantOptions participant = options_.participant;
    participant.name = std::string(contract::kServiceParticipantPrefix) + options_.name;
    participant.cell = options_.name;
    contract::SetupReport report;
    auto joined = participant_.join(participant, report);
    // Before the outcome: an ignored option may explain a failure.
    for (const auto& warning : report.warnings) spdlog::warn("{}", warning);
    for (const auto& note : report.notes) spdlog::info("{}", note);
    if (!joined) return joined;
  }
  if (const auto& cell = participant_->published_cell()) {
    spdlog::info("publishing in the default partition and in '{}', for followers of the cell",
                 *cell);
  }
  if (!options_.participant.security_dir.empty()) {
    spdlog::info("DDS Security on: identity '{}' in '{}'", options_.participant.security_identity,
                 options_.participant.security_dir);
  }
  if (auto claimed = claim_name(taking_over); !claimed) return claimed;
  if (!taking_over && options_.before_serving) {
    auto cleared = options_.before_serving(std::move(setups));
    if (!cleared) return fail(cleared.error());
    setups = std::move(*cleared);
  }
  if (auto created = create_writers(); !created) return created;

  for (auto& setup : setups) {
    std::vector<std::uint8_t> configured;
    for (const auto& hand : setup.hands) configured.push_back(hand.can_id);
    // Known to the publisher before the scheduler exists: it may report
    // (states, never events) from its constructor.
    const std::uint16_t index = statuses_.add_bus(setup.name, setup.bus->spec(), configured);
    auto& observer = observers_.emplace_back(std::make_unique<BusObserver>(statuses_, index));
    setup.scheduler.allow_admin = options_.allow_admin;
    schedulers_.push_back(std::make_unique<hand::BusScheduler>(
        setup.name, std::move(setup.bus), setup.hands, setup.scheduler, clock_, *observer));
    schedulers_.back()->warm(setup.warm);
    statuses_.set_link_up(index, schedulers_.back()->link_state() == bus::LinkState::up);
    directory_.add_bus(setup.name, schedulers_.back()->roster());
  }
  // Before the first statuses (start()), which show each hand's holder.
  if (taking_over) load_leases(standby.leases);
  return {};
}

void Service::Impl::load_leases(const std::vector<HandedLease>& handed) {
  std::vector<HeldLease> leases;
  for (const auto& lease : handed) {
    const auto bus = directory_.find_bus(lease.bus);
    if (!bus) continue;  // a bus the primary had and this configuration has not
    leases.push_back({{*bus, lease.can_id}, lease.holder_id, lease.holder, lease.left});
    spdlog::info("{}: lease of '{}' (participant {}) carried over, {} ms left",
                 hand_text(lease.bus, lease.can_id), lease.holder, lease.holder_id,
                 std::chrono::duration_cast<std::chrono::milliseconds>(lease.left).count());
  }
  // Each loaded lease is written at once: a standby of this service knows it too.
  leases_.load(leases);
}

Result<void, std::string> Service::Impl::claim_name(bool standby) {
  msg::ServiceOwner self = own_claim(options_.name, options_.host, statuses_.started_ns());
  self.epoch(options_.epoch_floor);
  if (standby) return owner_->take_over(std::move(self), options_.on_lost_ownership);
  if (auto created = owner_->create(*participant_); !created) {
    return fail(cannot_create(created.error()));
  }
  const Duration window = options_.claim_window.value_or(contract::kStartClaimWindow);
  spdlog::info("listening {} ms for another service named '{}' before serving",
               std::chrono::duration_cast<std::chrono::milliseconds>(window).count(),
               options_.name);
  return owner_->claim(std::move(self), window, options_.on_lost_ownership);
}

std::string Service::Impl::cannot_create(const std::string& what) const {
  return dds::cannot_create(what, options_.participant, *participant_);
}

Result<void, std::string> Service::Impl::create_writers() {
  const WriterListeners listeners{replies_.reply_listener(), replies_.group_reply_listener()};
  if (drains_) {  // a standby's, made before its takeover
    endpoints_.listen(listeners);
  } else if (auto created = endpoints_.create_writers(*participant_, listeners); !created) {
    return fail(cannot_create(created.error()));
  }
  statuses_.set_writers(endpoints_.status, endpoints_.event, endpoints_.info);
  replies_.set_reply_writer(endpoints_.reply);
  replies_.set_group_reply_writer(endpoints_.group_reply);
  create_lease_writer();
  return {};
}

void Service::Impl::create_lease_writer() {
  fdds::Topic* topic = participant_->topics().lease;
  fdds::DataWriter* writer = topic == nullptr
                                 ? nullptr
                                 : participant_->publisher().create_datawriter(
                                       topic, contract::writer_qos(TopicRole::hand_lease), nullptr,
                                       fdds::StatusMask::none());
  if (writer == nullptr) {
    spdlog::warn("a standby will not know the leases: {}",
                 cannot_create(std::string("the writer of ") + dh3::topics::HAND_LEASE));
  }
  lease_share_.set_writer(writer);
}

Result<void, std::string> Service::Impl::create_readers() {
  const ReaderListeners listeners{&request_listener_, &admin_request_listener_,
                                  &group_request_listener_};
  if (drains_) {
    serve_kept();
  } else if (auto created = endpoints_.create_readers(*participant_, listeners); !created) {
    return fail(cannot_create(created.error()));
  }
  if (endpoints_.admin_request == nullptr && options_.allow_admin) {
    spdlog::warn("administrative commands are refused: {}",
                 cannot_create("the reader of " + std::string(dh3::topics::ADMIN_REQUEST)));
  }
  if (endpoints_.group_request == nullptr) {
    spdlog::warn("group commands are off: {}",
                 cannot_create("the group request reader and reply writer"));
  }
  return {};
}

Result<void, std::string> Service::Impl::start() {
  if (started_) return {};
  started_ = true;
  statuses_.publish_info();
  for (std::size_t i = 0; i < schedulers_.size(); ++i) {
    statuses_.publish_first(static_cast<std::uint16_t>(i), schedulers_[i]->state());
  }
  for (auto& scheduler : schedulers_) scheduler->start();
  timer_.start();
  // Last: requests are only taken once everything they need runs, and
  // knows which topic may carry administrative commands.
  requests_.set_access_control(participant_->access_control());
  requests_.set_rate(&rate_);
  if (auto created = create_readers(); !created) return created;
  spdlog::info("service '{}' on DDS domain {}: {} bus(es), admin commands {}", options_.name,
               options_.participant.domain, schedulers_.size(),
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
  timer_.stop();
  // The schedulers end their pending commands CANCELLED and report hands offline.
  for (auto& scheduler : schedulers_) scheduler->stop();
  requests_.cancel_scans();
  // Whatever the schedulers did not report, every hand goes out offline.
  statuses_.publish_all_offline();
  // Replies still waiting for their reader go out now, to the writer's history.
  replies_.write_all_held();
  // Subscribers get the offline samples and last replies before we leave.
  const auto deadline = SteadyClock::now() + options_.shutdown_ack_timeout;
  for (fdds::DataWriter* writer :
       {endpoints_.status, endpoints_.reply, endpoints_.event, endpoints_.group_reply}) {
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
  if (!participant_.joined()) return;
  owner_->stop();
  endpoints_.listen(ReaderListeners{});
  replies_.detach();
  statuses_.detach();
  lease_share_.set_writer(nullptr);
  endpoints_ = {};
  participant_.leave();
}

// ---------------------------------------------------------------------------
// Requests, departures and expiry

void Service::Impl::on_requests(fdds::DataReader& reader, RequestTopic topic) {
  std::lock_guard lock(dispatch_mutex_);
  // In batches, each served one client at a time (round_robin.hpp): a flood
  // taken ahead of another client's request does not make it wait.
  std::vector<Caller> callers;
  for (;;) {
    intake_.clear();
    callers.clear();
    fdds::SampleInfo info;
    while (intake_.size() < kIntakeBatch) {
      msg::CommandRequest& request = intake_.emplace_back();
      if (reader.take_next_sample(&request, &info) != ReturnCode_t::RETCODE_OK) {
        intake_.pop_back();
        break;
      }
      if (!serves(info)) {
        intake_.pop_back();
        continue;
      }
      callers.push_back(caller_of(info));
    }
    if (intake_.empty()) return;
    serve_intake(callers, topic);
  }
}

void Service::Impl::serve_intake(std::vector<Caller>& callers, RequestTopic topic) {
  std::vector<std::string> caller_ids;
  for (std::size_t i = 0; i < intake_.size(); ++i) {
    if (options_.test_seam_tracer)
      options_.test_seam_tracer(TracePoint::request_taken, intake_[i].request_seq());
    caller_ids.push_back(callers[i].id);
  }
  for (const std::size_t i : round_robin_order(caller_ids)) {
    requests_.handle(intake_[i], callers[i], stopping_, topic);
  }
}

void Service::Impl::serve_kept() {
  // Held while the drains switch: a request that comes after waits in the
  // listener for these to be served.
  std::lock_guard lock(dispatch_mutex_);
  const auto serve = [this](auto& drain, fdds::DataReaderListener& listener, RequestTopic topic) {
    std::vector<Caller> callers;
    intake_.clear();
    for (auto& kept : drain.forward_to(&listener)) {
      if (!serves(kept.info)) continue;
      intake_.push_back(std::move(kept.request));
      callers.push_back(caller_of(kept.info));
    }
    if (!intake_.empty()) serve_intake(callers, topic);
  };
  serve(drains_->commands, request_listener_, RequestTopic::commands);
  serve(drains_->admin, admin_request_listener_, RequestTopic::admin);
  for (auto& kept : drains_->groups.forward_to(&group_request_listener_)) {
    if (serves(kept.info)) groups_.handle(kept.request, caller_of(kept.info), stopping_);
  }
}

void Service::Impl::on_group_requests(fdds::DataReader& reader) {
  std::lock_guard lock(dispatch_mutex_);
  fdds::SampleInfo info;
  while (reader.take_next_sample(&group_request_, &info) == ReturnCode_t::RETCODE_OK) {
    if (serves(info)) groups_.handle(group_request_, caller_of(info), stopping_);
  }
}

bool Service::Impl::serves(const fdds::SampleInfo& info) {
  // Outranked by another service of this name: that one answers.
  if (!info.valid_data || !owner_->owns()) return false;
  if (!contract::addressed_elsewhere(info, participant_->participant().guid().guidPrefix)) {
    return true;
  }
  // Written to the service this one took over from, or to one before it:
  // the caller's call ends with that one's loss (request_address.hpp).
  spdlog::debug("a request of participant {} written to another incarnation of '{}' is dropped",
                contract::client_id_for(info.publication_handle), options_.name);
  return false;
}

Caller Service::Impl::caller_of(const fdds::SampleInfo& info) const {
  std::string id = contract::client_id_for(info.publication_handle);
  std::string shown = names_.shown_as(id);
  return {std::move(id), std::move(shown)};
}

contract::PeerDiscoveryListener::Callbacks Service::Impl::peer_callbacks() {
  return {[this](const std::string& participant_id, const std::string& name) {
            spdlog::debug("participant {} '{}': discovered", participant_id, name);
            owner_->announced(participant_id, name);
            replies_.participant_joined(participant_id);
          },
          [this](const std::string& participant_id, bool dropped) {
            spdlog::debug("participant {}: {}", participant_id,
                          dropped ? "dropped (lease expired)" : "left");
            on_participant_left(participant_id, dropped);
          },
          [this](const eprosima::fastrtps::rtps::ParticipantProxyData& data) {
            names_.discovered(data);
          }};
}

void Service::Impl::on_participant_left(const std::string& participant_id, bool dropped) {
  if (const std::size_t dropped_replies = replies_.participant_left(participant_id)) {
    spdlog::info("{} held replies to {} dropped: it left before its reply reader matched",
                 dropped_replies, participant_id);
  }
  for (const auto& ended : leases_.drop_client(participant_id)) {
    spdlog::info("{}: lease of '{}' (participant {}) ended, its participant {} the domain",
                 hand_text(directory_.bus_name(ended.hand.bus), ended.hand.can_id), ended.holder,
                 ended.holder_id, dropped ? "dropped out of" : "left");
    statuses_.republish(ended.hand);
  }
  names_.forget(participant_id);
  rate_.forget(participant_id);
  owner_->left(participant_id);
}

void Service::Impl::sweep_expired() {
  replies_.write_expired();
  for (const auto& ended : leases_.expire()) {
    spdlog::info("{}: lease of '{}' (participant {}) expired",
                 hand_text(directory_.bus_name(ended.hand.bus), ended.hand.can_id), ended.holder,
                 ended.holder_id);
    statuses_.republish(ended.hand);
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

Result<std::unique_ptr<Service>, std::string> Service::take_over(ServiceOptions options,
                                                                 std::vector<BusSetup> buses,
                                                                 const Clock& clock,
                                                                 StandbyPresence& standby) {
  auto impl = std::make_unique<Impl>(std::move(options), clock);
  if (auto ok = impl->init(std::move(buses), standby.hand_over()); !ok) return fail(ok.error());
  return std::unique_ptr<Service>(new Service(std::move(impl)));
}

Result<void, std::string> Service::start() {
  return impl_->start();
}
std::vector<hand::BusMetrics> Service::metrics() const {
  return impl_->metrics();
}
Service::Refusals Service::refusals() const {
  return impl_->refusals();
}
void Service::stop() {
  impl_->stop();
}

}  // namespace dh3::dds
