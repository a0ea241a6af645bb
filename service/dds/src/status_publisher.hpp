#pragma once
// What the service publishes of its hands: one status sample per hand (its
// HandSlot), the hands' events and the service info.
//
// Threading: a bus's reports come from its loop, its hands' samples also from
// requests and lease changes; each bus's mutex orders them (see the members).

#include <array>
#include <atomic>
#include <cstdint>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "dh3/base/clock.hpp"
#include "dh3/bus/bus.hpp"
#include "dh3/contract/dh3.h"
#include "dh3/dds/service.hpp"
#include "dh3/hand/hand_types.hpp"
#include "hand_directory.hpp"
#include "lease_table.hpp"

namespace dh3::dds {

class StatusPublisher {
 public:
  StatusPublisher(const ServiceOptions& options, const Clock& clock, const LeaseTable& leases,
                  const HandDirectory& directory);
  StatusPublisher(const StatusPublisher&) = delete;
  StatusPublisher& operator=(const StatusPublisher&) = delete;

  /// A bus before its scheduler exists (it may report from its constructor);
  /// its configured hands are in the service info from the start. Returns its index.
  std::uint16_t add_bus(std::string name, std::string spec,
                        const std::vector<std::uint8_t>& configured);
  /// The link as the bus's scheduler first found it (then on_link).
  void set_link_up(std::uint16_t bus, bool up) { buses_[bus]->link_up = up; }
  /// Set once at set-up (any may be null: its samples are not written).
  void set_writers(eprosima::fastdds::dds::DataWriter* status,
                   eprosima::fastdds::dds::DataWriter* event,
                   eprosima::fastdds::dds::DataWriter* info);
  void detach() { set_writers(nullptr, nullptr, nullptr); }

  // The bus loop's reports (HandObserver). A state is held, prepared but not
  // sent, until its batch ends (send_held): the commands that ended with it
  // are answered first, their replies carrying it (attach_to), so a
  // state-changing command's reply does not wait for a status sample.
  void on_state(std::uint16_t bus, const hand::HandState& state);
  /// The same values read again: published if the read time the samples
  /// carry is older than options.status_refresh (or one is held). A sample
  /// sent again for a lease carries the old read time: it does not count.
  void on_fresh(std::uint16_t bus, const hand::HandState& state);
  /// Sends a held status first: statuses go out before the events they explain.
  void on_event(std::uint16_t bus, const hand::HandEvent& event);
  void on_link(std::uint16_t bus, bus::LinkState state);
  /// Sends the hand's held sample, if any (the end of a batch, or of a lease change).
  void send_held(std::uint16_t bus, std::uint8_t can_id);

  /// Publishes each state of a hand that has no sample yet (start).
  void publish_first(std::uint16_t bus, const std::vector<hand::HandState>& states);
  /// Every hand still published online goes out offline (stop).
  void publish_all_offline();
  void publish_info();
  /// When the service started (its ServiceInfo's and its owner claim's started_ns).
  [[nodiscard]] std::uint64_t started_ns() const { return started_ns_; }

  /// Copies the hand's last prepared sample (sent or held) into the reply;
  /// leaves the reply's empty (update_seq 0) if the hand has none.
  void attach_to(msg::CommandReply& reply, std::uint16_t bus, std::uint8_t can_id);
  /// A new sample of the hand (its lease holder changed), written now.
  void republish(HandKey hand);
  /// A new sample of the hand (its lease holder changed), held: copied into
  /// `reply` for the reply to go first; send_held() sends it after.
  void hold_republished(HandKey hand, msg::CommandReply& reply);

 private:
  struct HandSlot {
    std::uint64_t update_seq = 0;
    bool announced = false;  ///< the service info lists it
    bool written = false;    ///< `sample` was filled from a reported state
    bool held = false;       ///< `sample` is prepared and not sent yet
    /// When `sample` last took the hand's state, and so its read time; a
    /// lease's republication keeps both.
    TimePoint state_at{};
    msg::HandStatus sample;  ///< the last sample, reused for every sample of this hand
  };
  struct BusStatus {
    std::string name;
    std::string spec;
    std::atomic<bool> link_up{false};
    /// Orders the status samples of this bus's hands: the bus thread and lease
    /// changes both publish, and the last sample written must be the newest.
    /// Held while writing; under it status_write_mutex_, then info_mutex_.
    std::mutex mutex;
    std::array<std::unique_ptr<HandSlot>, 256> hands{};  ///< under mutex
    msg::HandEvent event_sample;                         ///< reused; under mutex
  };

  static HandSlot& slot_locked(BusStatus& bus, std::uint8_t can_id);
  /// `hold`: prepare the sample and leave it for send_held().
  void on_state_locked(std::uint16_t bus, const hand::HandState& state, bool hold);
  /// Gives the slot's sample its lease holder, next update_seq and time.
  void prepare_locked(std::uint16_t bus, std::uint8_t can_id, HandSlot& slot);
  void send_locked(std::uint16_t bus, std::uint8_t can_id, HandSlot& slot);
  /// A hand-layer (steady) time on the wall clock, ns since the epoch; 0 for "never".
  [[nodiscard]] std::uint64_t wall_clock_ns_of(TimePoint time) const;

  const ServiceOptions& options_;
  const Clock& clock_;
  const LeaseTable& leases_;
  const HandDirectory& directory_;
  std::vector<std::unique_ptr<BusStatus>> buses_;  ///< fixed after set-up
  const std::uint64_t started_ns_;
  std::atomic<std::uint64_t> event_seq_{0};
  eprosima::fastdds::dds::DataWriter* status_writer_ = nullptr;
  eprosima::fastdds::dds::DataWriter* event_writer_ = nullptr;
  eprosima::fastdds::dds::DataWriter* info_writer_ = nullptr;
  /// Status is keyed, and the generated type computes a sample's key in one
  /// buffer of its own: two buses' threads writing at once would mix up their
  /// hands' instances (ThreadSanitizer found it). Bus mutexes only order one
  /// bus's samples, so writes to the status writer take this as well.
  std::mutex status_write_mutex_;
  std::mutex info_mutex_;  ///< one service info sample at a time
};

}  // namespace dh3::dds
