#pragma once
// A standby's reader of the lease topic (dh3/hand_lease): every lease sample
// of its cell goes into a LeaseMirror under the writer's participant, and at
// the takeover the leases of the owner it takes over from are handed to the
// service (StandbyPresence::Handover). The active service's side is
// LeasePublisher.
//
// Threads: Fast DDS's listener thread fills the mirror; held_by_writer() from
// any thread. Deleted before the participant it reads on.

#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "dh3/base/result.hpp"
#include "dh3/contract/participant_setup.hpp"
#include "lease_mirror.hpp"

namespace dh3::dds {

class LeaseFollower final : public eprosima::fastdds::dds::DataReaderListener {
 public:
  /// Reads the lease samples of `service` on `participant`; fails naming
  /// what it could not create (DDS Security permissions that predate the topic).
  static Result<std::unique_ptr<LeaseFollower>, std::string> create(
      contract::Participant& participant, const std::string& service);
  ~LeaseFollower() override;
  LeaseFollower(const LeaseFollower&) = delete;
  LeaseFollower& operator=(const LeaseFollower&) = delete;

  /// The leases participant `writer` last said were held, with their time left now.
  [[nodiscard]] std::vector<HandedLease> held_by_writer(const std::string& writer) const;

  void on_data_available(eprosima::fastdds::dds::DataReader* reader) override;

 private:
  LeaseFollower(contract::Participant& participant, const std::string& service)
      : participant_(participant), mirror_(service) {}

  contract::Participant& participant_;
  eprosima::fastdds::dds::DataReader* reader_ = nullptr;
  mutable std::mutex mutex_;
  LeaseMirror mirror_;  ///< under mutex_
};

}  // namespace dh3::dds
