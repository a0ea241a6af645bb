#pragma once
// Loop thread: on_link_lost(), on_reported() and up(). Any thread: state() and
// reconnects(), which the scheduler's metrics read.
//
// Whether the bus's link is up, as the loop last saw it. The link goes down
// when an operation on the bus (a receive or a send) fails with link_down; it
// is up again when the bus's link_state() says so after a receive that did
// not fail with it, once a reconnecting backend is back. Each change is reported once;
// the scheduler tells the drivers, the scan and the observer.

#include <atomic>
#include <cstdint>

#include "dh3/bus/bus.hpp"

namespace dh3::hand {

enum class LinkChange : std::uint8_t {
  none,
  went_down,  ///< it was up
  came_up,    ///< it was down; counted as a reconnect
};

class LinkMonitor {
 public:
  /// `initial`: the bus's link state when the scheduler was made.
  explicit LinkMonitor(bus::LinkState initial)
      : up_(initial == bus::LinkState::up), state_(initial) {}

  /// A receive or a send failed with link_down.
  LinkChange on_link_lost();
  /// After a receive that did not fail with link_down: the bus's link_state().
  LinkChange on_reported(bus::LinkState reported);

  [[nodiscard]] bool up() const { return up_; }
  [[nodiscard]] bus::LinkState state() const { return state_.load(); }
  /// Times the link came back after it was down.
  [[nodiscard]] std::uint64_t reconnects() const { return reconnects_.load(); }

 private:
  bool up_;  ///< loop thread's copy of state_ == up
  std::atomic<bus::LinkState> state_;
  std::atomic<std::uint64_t> reconnects_{0};
};

}  // namespace dh3::hand
