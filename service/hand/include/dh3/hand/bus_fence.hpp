#pragma once
// The bus's word on whether another service still drives it. DDS may say the
// active service is gone (a partition, a frozen participant) while its process
// still sends on the bus; two masters on one DH-3 bus complete on each other's
// echoes. So a standby takes over a bus only once it has seen no request there
// for `quiet`: longer than the active service's longest gap between two frames
// (with hands listed it polls each at least every poll_interval_idle).
// Pure: told every request seen and the time; single-threaded.

#include "dh3/base/clock.hpp"

namespace dh3::hand {

class BusFence {
 public:
  /// `watching_since`: when the standby began to watch (a bus never heard from
  /// is not clear before `quiet` has passed since then either).
  BusFence(Duration quiet, TimePoint watching_since)
      : quiet_(quiet), last_request_(watching_since) {}

  /// A request of another service was seen on the bus at `at`.
  void on_request(TimePoint at) {
    if (at > last_request_) last_request_ = at;
  }
  /// No request in the `quiet` before `now`: nobody else drives the bus.
  [[nodiscard]] bool clear(TimePoint now) const { return now - last_request_ >= quiet_; }
  /// When clear() turns true unless another request comes first.
  [[nodiscard]] TimePoint clear_at() const { return last_request_ + quiet_; }
  [[nodiscard]] TimePoint last_request() const { return last_request_; }
  [[nodiscard]] Duration quiet() const { return quiet_; }

 private:
  Duration quiet_;
  TimePoint last_request_;
};

}  // namespace dh3::hand
