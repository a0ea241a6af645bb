#pragma once
// The service's claim on its cell name (docs/failover.md): its owner writer,
// whose liveliness it asserts from a thread of its own (so a frozen or
// cut-off process stops asserting, and every reader sees it dead within the
// owner lease), and its owner reader, through which it meets any other
// service of its name.
//
// At start it listens for contract::kStartClaimWindow before it claims the
// name: a live active owner found meanwhile makes claim() fail, naming that
// owner's host and process. Once serving it keeps applying the ownership
// rule (contract::outranks): when a higher-ranking live owner of its name
// appears (two services that met after a partition healed), owns() turns
// false at once and `lost` runs once, on the beacon's thread.
//
// Threads: Fast DDS listener threads fill the table; the beacon's thread
// asserts and judges; owns() from any thread. One mutex guards the table.

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "dh3/base/clock.hpp"
#include "dh3/base/result.hpp"
#include "dh3/contract/dh3.h"
#include "dh3/contract/ownership.hpp"
#include "dh3/contract/participant_setup.hpp"

namespace dh3::dds {

class OwnerBeacon {
 public:
  using Lost = std::function<void(const std::string& why)>;

  explicit OwnerBeacon(const Clock& clock) : clock_(clock), listener_(*this) {}
  ~OwnerBeacon();
  OwnerBeacon(const OwnerBeacon&) = delete;
  OwnerBeacon& operator=(const OwnerBeacon&) = delete;

  /// Creates the owner writer and reader on `participant` (nothing is written
  /// yet); fails naming the endpoint it could not create.
  Result<void, std::string> create(contract::Participant& participant);
  /// Listens for `window`, then claims the name `self` describes (its epoch
  /// set above every claim seen, and at least self.epoch()) and asserts it
  /// from then on; fails, naming the other service, if the name has a live
  /// active owner.
  Result<void, std::string> claim(msg::ServiceOwner self, Duration window, Lost lost);
  /// Writes `self` as a standby's claim (ROLE_STANDBY: it never owns, so no
  /// client takes it for the service) and asserts it from then on.
  Result<void, std::string> stand_by(msg::ServiceOwner self);
  /// A standby's claim becomes the owner's: `self` (role ACTIVE) is written
  /// with an epoch above every claim seen and at least self.epoch(), at once,
  /// and defended as claim() defends it.
  Result<void, std::string> take_over(msg::ServiceOwner self, Lost lost);
  /// The owner of `service` as the claims and liveliness seen tell now
  /// (contract::OwnerTable::owner), and the highest epoch claimed on it.
  [[nodiscard]] std::optional<contract::OwnerClaim> owner(const std::string& service) const;
  [[nodiscard]] std::uint64_t highest_epoch(const std::string& service) const;
  /// Runs `read` on the claims seen under the table's lock, so that what it
  /// reads is of one moment; `read` must be quick. Any thread.
  template <class Read>
  auto read_table(Read&& read) const {
    std::lock_guard lock(mutex_);
    return read(static_cast<const contract::OwnerTable&>(table_));
  }
  /// Still the owner of the name: false once another outranks it.
  [[nodiscard]] bool owns() const { return owns_.load(); }
  /// The claim as written (epoch included), once claim() succeeded.
  [[nodiscard]] const msg::ServiceOwner& self() const { return self_; }
  /// Stops asserting and lets go of the endpoints; before the participant is deleted.
  void stop();
  /// Discovery announced `participant` under `participant_name`: if that is a
  /// service's or a standby's (which serves under that name once it took
  /// over), a claim still starting, or a standby judging its cell vacant,
  /// waits for its claim sample too (contract::kStartClaimAwait). Any thread.
  void announced(const std::string& participant, std::string_view participant_name);
  /// `participant` left the domain. Any thread.
  void left(const std::string& participant);

 private:
  class Listener final : public eprosima::fastdds::dds::DataReaderListener {
   public:
    explicit Listener(OwnerBeacon& beacon) : beacon_(beacon) {}
    void on_data_available(eprosima::fastdds::dds::DataReader* reader) override;
    void on_liveliness_changed(
        eprosima::fastdds::dds::DataReader* reader,
        const eprosima::fastdds::dds::LivelinessChangedStatus& status) override;
    void on_subscription_matched(
        eprosima::fastdds::dds::DataReader* reader,
        const eprosima::fastdds::dds::SubscriptionMatchedStatus& status) override;

   private:
    OwnerBeacon& beacon_;
  };

  void run();
  /// The loser's verdict, once; under mutex_.
  [[nodiscard]] std::string outranked_locked() const;

  const Clock& clock_;
  Listener listener_;
  eprosima::fastdds::dds::DataWriter* writer_ = nullptr;
  eprosima::fastdds::dds::DataReader* reader_ = nullptr;
  std::string participant_;  ///< our own GUID prefix in hex
  msg::ServiceOwner self_;
  Lost lost_;

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  contract::OwnerTable table_;  ///< under mutex_
  bool stopping_ = false;       ///< under mutex_
  std::atomic<bool> owns_{false};
  bool standing_by_ = false;  ///< under mutex_: asserting a standby's claim
  std::thread thread_;
};

/// The claim a service makes: `service` served by this process on `host`.
msg::ServiceOwner own_claim(const std::string& service, const std::string& host,
                            std::uint64_t started_ns);

}  // namespace dh3::dds
