// OwnerBeacon: the service's claim on its cell name, asserted and defended.

#include "owner_beacon.hpp"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <fastdds/dds/core/status/LivelinessChangedStatus.hpp>
#include <fastdds/dds/core/status/SubscriptionMatchedStatus.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>

#include "dh3/contract/participant.hpp"
#include "dh3/contract/qos.hpp"

namespace dh3::dds {
namespace fdds = eprosima::fastdds::dds;
using eprosima::fastrtps::types::ReturnCode_t;

namespace {

/// The cell name of a participant announced as a service or as a standby.
std::optional<std::string> claimant_of(std::string_view participant_name) {
  if (auto service = contract::announced_service(participant_name)) return service;
  if (!participant_name.starts_with(contract::kStandbyParticipantPrefix)) return std::nullopt;
  return std::string(participant_name.substr(contract::kStandbyParticipantPrefix.size()));
}

}  // namespace

msg::ServiceOwner own_claim(const std::string& service, const std::string& host,
                            std::uint64_t started_ns) {
  msg::ServiceOwner claim;
  claim.service(service);
  claim.host(host);
  claim.pid(static_cast<std::int32_t>(::getpid()));
  claim.started_ns(started_ns);
  claim.role(msg::ServiceRole::ROLE_ACTIVE);
  return claim;
}

OwnerBeacon::~OwnerBeacon() {
  stop();
}

Result<void, std::string> OwnerBeacon::create(contract::Participant& participant) {
  participant_ = participant.client_id();
  fdds::Topic* topic = participant.topics().owner;
  writer_ = participant.publisher().create_datawriter(
      topic, contract::writer_qos(contract::TopicRole::service_owner), nullptr,
      fdds::StatusMask::none());
  if (writer_ == nullptr) return fail("the writer of " + topic->get_name());
  reader_ = participant.subscriber().create_datareader(
      topic, contract::reader_qos(contract::TopicRole::service_owner), &listener_,
      fdds::StatusMask::data_available()
          << fdds::StatusMask::liveliness_changed() << fdds::StatusMask::subscription_matched());
  if (reader_ == nullptr) return fail("the reader of " + topic->get_name());
  return {};
}

Result<void, std::string> OwnerBeacon::claim(msg::ServiceOwner self, Duration window, Lost lost) {
  contract::StartClaim start(self.service(), participant_, window, clock_);
  {
    std::unique_lock lock(mutex_);
    for (;;) {
      const auto verdict = start.decide(table_);
      if (verdict == contract::StartClaim::Verdict::refuse) {
        return fail("service '" + self.service() + "' is already served on this domain by " +
                    start.other()->describe() +
                    "; a second service of one name never serves (configure it as that "
                    "cell's standby, or give it another name)");
      }
      if (verdict == contract::StartClaim::Verdict::serve) break;
      // Woken by every claim and liveliness change; the clock decides the end.
      wake_.wait_for(lock, std::chrono::milliseconds(20));
    }
    self.epoch(std::max(start.epoch(table_), self.epoch()));
    self_ = self;
    lost_ = std::move(lost);
  }
  if (!writer_->write(&self_)) {
    return fail("cannot write the service's owner sample");
  }
  owns_ = true;
  spdlog::info("service '{}' claimed (epoch {}), liveliness asserted every {} ms, lease {} ms",
               self_.service(), self_.epoch(), contract::kOwnerAssertPeriod.count(),
               contract::kOwnerLease.count());
  thread_ = std::thread([this] { run(); });
  return {};
}

Result<void, std::string> OwnerBeacon::stand_by(msg::ServiceOwner self) {
  self.role(msg::ServiceRole::ROLE_STANDBY);
  {
    std::lock_guard lock(mutex_);
    self_ = self;
    standing_by_ = true;
  }
  if (!writer_->write(&self_)) {
    return fail("cannot write the standby's owner sample");
  }
  spdlog::info("standby for service '{}': watching its owner, serving nothing", self_.service());
  thread_ = std::thread([this] { run(); });
  return {};
}

Result<void, std::string> OwnerBeacon::take_over(msg::ServiceOwner self, Lost lost) {
  {
    std::lock_guard lock(mutex_);
    self.role(msg::ServiceRole::ROLE_ACTIVE);
    self.epoch(std::max(table_.highest_epoch(self.service()) + 1, self.epoch()));
    self_ = self;
    lost_ = std::move(lost);
    standing_by_ = false;
  }
  if (!writer_->write(&self_)) return fail("cannot write the service's owner sample");
  owns_ = true;
  wake_.notify_all();
  spdlog::info("service '{}' taken over (epoch {}) on the standby's participant", self_.service(),
               self_.epoch());
  return {};
}

std::optional<contract::OwnerClaim> OwnerBeacon::owner(const std::string& service) const {
  std::lock_guard lock(mutex_);
  return table_.owner(service);
}

std::uint64_t OwnerBeacon::highest_epoch(const std::string& service) const {
  std::lock_guard lock(mutex_);
  return table_.highest_epoch(service);
}

void OwnerBeacon::run() {
  // Assertions keep their period whatever wakes the thread (every claim and
  // liveliness change does), and go out without the table's lock: a listener
  // busy with the table never delays one.
  auto next_assert = std::chrono::steady_clock::now();
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    if (!owns_ && !standing_by_) {
      wake_.wait(lock);
      continue;
    }
    if (const std::string why = owns_ ? outranked_locked() : std::string(); !why.empty()) {
      owns_ = false;
      spdlog::error("{}", why);
      lock.unlock();
      if (lost_) lost_(why);
      lock.lock();
      continue;
    }
    if (std::chrono::steady_clock::now() >= next_assert) {
      lock.unlock();
      writer_->assert_liveliness();
      lock.lock();
      next_assert = std::chrono::steady_clock::now() + contract::kOwnerAssertPeriod;
    }
    wake_.wait_until(lock, next_assert);
  }
}

std::string OwnerBeacon::outranked_locked() const {
  const auto owner = table_.owner(self_.service());
  if (!owner || owner->participant == participant_) return {};
  if (!contract::outranks(*owner, contract::to_claim(self_, participant_))) return {};
  return "service '" + self_.service() + "' is also served by " + owner->describe() +
         " with epoch " + std::to_string(owner->epoch) + ", which outranks this one (epoch " +
         std::to_string(self_.epoch()) + "): this service stops serving";
}

void OwnerBeacon::announced(const std::string& participant, std::string_view participant_name) {
  auto service = claimant_of(participant_name);
  if (!service) return;
  {
    std::lock_guard lock(mutex_);
    table_.announced(participant, std::move(*service));
  }
  wake_.notify_all();
}

void OwnerBeacon::left(const std::string& participant) {
  {
    std::lock_guard lock(mutex_);
    table_.forget(participant);
  }
  wake_.notify_all();
}

void OwnerBeacon::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  if (reader_ != nullptr) reader_->set_listener(nullptr);
  // Deleted with the participant, which may go next.
  reader_ = nullptr;
  writer_ = nullptr;
}

void OwnerBeacon::Listener::on_data_available(fdds::DataReader* reader) {
  msg::ServiceOwner sample;
  fdds::SampleInfo info;
  while (reader->take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data) continue;
    const std::string from = contract::client_id_for(info.publication_handle);
    std::lock_guard lock(beacon_.mutex_);
    beacon_.table_.claim(contract::to_claim(sample, from));
  }
  beacon_.wake_.notify_all();
}

void OwnerBeacon::Listener::on_liveliness_changed(fdds::DataReader* /*reader*/,
                                                  const fdds::LivelinessChangedStatus& status) {
  const std::string from = contract::client_id_for(status.last_publication_handle);
  {
    std::lock_guard lock(beacon_.mutex_);
    if (status.alive_count_change != 0) {
      beacon_.table_.set_alive(from,
                               beacon_.table_.liveliness_changed(from, status.alive_count_change));
    }
  }
  beacon_.wake_.notify_all();
}

void OwnerBeacon::Listener::on_subscription_matched(fdds::DataReader* /*reader*/,
                                                    const fdds::SubscriptionMatchedStatus& status) {
  if (status.current_count_change >= 0) return;
  std::lock_guard lock(beacon_.mutex_);
  beacon_.table_.forget(contract::client_id_for(status.last_publication_handle));
}

}  // namespace dh3::dds
