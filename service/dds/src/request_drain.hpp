#pragma once
// A standby's request readers (service_endpoints.hpp) hear nothing but this
// until the service that takes over serves them. Before the takeover it
// takes every request as it arrives and drops it: the active service answers
// it, and the readers, KEEP_ALL as the service's are, would otherwise hold
// them all and in the end slow every client's writer by flow control. From
// hold() on, just before the standby's claim turns active, it keeps what it
// takes: written after that, it is the new owner's. forward_to() hands the
// service what was kept and passes everything after it to the service's own
// listener, so no request waits in a reader with nobody to tell.
//
// Thread-safe. Fast DDS calls on_data_available with the reader's lock held;
// a kept request is taken and stored under this drain's mutex, forwarding
// happens outside it. forward_to() takes only this mutex, so its caller may
// hold the lock its listener's callbacks take (the service's dispatch mutex)
// and serve what it got before any request that came after.

#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <mutex>
#include <vector>

#include "dh3/contract/dh3.h"

namespace dh3::dds {

template <typename Request>
class RequestDrain final : public eprosima::fastdds::dds::DataReaderListener {
 public:
  struct Kept {
    Request request;
    eprosima::fastdds::dds::SampleInfo info;
  };

  void on_data_available(eprosima::fastdds::dds::DataReader* reader) override {
    eprosima::fastdds::dds::DataReaderListener* target = nullptr;
    {
      std::lock_guard lock(mutex_);
      target = target_;
      if (target == nullptr) {
        Kept sample;
        while (reader->take_next_sample(&sample.request, &sample.info) ==
               eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK) {
          if (holding_) kept_.push_back(sample);
        }
        return;
      }
    }
    target->on_data_available(reader);
  }

  /// From now on what arrives is kept.
  void hold() {
    std::lock_guard lock(mutex_);
    holding_ = true;
  }
  /// What was kept, in the order it came; from now on every arrival goes to
  /// `target` (which must outlive the reader's use of this drain).
  [[nodiscard]] std::vector<Kept> forward_to(eprosima::fastdds::dds::DataReaderListener* target) {
    std::lock_guard lock(mutex_);
    target_ = target;
    return std::move(kept_);
  }

 private:
  std::mutex mutex_;
  bool holding_ = false;                                          ///< under mutex_
  eprosima::fastdds::dds::DataReaderListener* target_ = nullptr;  ///< under mutex_
  std::vector<Kept> kept_;                                        ///< under mutex_
};

/// The drains of a standby's three request readers.
struct RequestDrains {
  RequestDrain<msg::CommandRequest> commands;
  RequestDrain<msg::CommandRequest> admin;
  RequestDrain<msg::GroupRequest> groups;
  void hold() {
    commands.hold();
    admin.hold();
    groups.hold();
  }
};

}  // namespace dh3::dds
