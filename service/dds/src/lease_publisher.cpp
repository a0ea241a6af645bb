#include "lease_publisher.hpp"

#include <spdlog/spdlog.h>

#include "lease_mirror.hpp"

namespace dh3::dds {

void LeasePublisher::publish(HandKey hand) {
  if (hand.bus >= directory_.bus_count()) return;
  std::lock_guard lock(mutex_);
  if (writer_ == nullptr) return;
  msg::HandLease sample =
      lease_sample(service_, directory_.bus_name(hand.bus), hand.can_id, leases_.lease_of(hand));
  if (!writer_->write(&sample)) {
    spdlog::warn("cannot write the lease of {} on bus '{}' for the standby", hand.can_id,
                 directory_.bus_name(hand.bus));
  }
}

}  // namespace dh3::dds
