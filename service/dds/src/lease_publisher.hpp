#pragma once
// The serving service's writer of the lease topic (dh3/hand_lease): each
// change of a hand's lease in its LeaseTable is written as that hand's lease
// sample (reliable, transient-local, the last one per hand), so that its
// standby knows every lease at the takeover (LeaseFollower). What is written
// is the table's state when the sample is written, under one mutex: of two
// changes of a hand told at once, the later state is the last written.
//
// Threads: any (requests, the expiry timer, the participant listener). The
// mutex is a leaf; the writer has no listener.

#include <fastdds/dds/publisher/DataWriter.hpp>
#include <mutex>
#include <string>

#include "hand_directory.hpp"
#include "lease_table.hpp"

namespace dh3::dds {

class LeasePublisher {
 public:
  LeasePublisher(std::string service, const LeaseTable& leases, const HandDirectory& directory)
      : service_(std::move(service)), leases_(leases), directory_(directory) {}

  /// Where to write; null: nothing is written (no writer could be made).
  void set_writer(eprosima::fastdds::dds::DataWriter* writer) {
    std::lock_guard lock(mutex_);
    writer_ = writer;
  }
  /// Writes `hand`'s lease as the table holds it now.
  void publish(HandKey hand);

 private:
  std::string service_;
  const LeaseTable& leases_;
  const HandDirectory& directory_;
  std::mutex mutex_;
  eprosima::fastdds::dds::DataWriter* writer_ = nullptr;  ///< under mutex_
};

}  // namespace dh3::dds
