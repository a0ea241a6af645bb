#include "link_monitor.hpp"

namespace dh3::hand {

LinkChange LinkMonitor::on_link_lost() {
  if (!up_) return LinkChange::none;
  up_ = false;
  state_.store(bus::LinkState::down);
  return LinkChange::went_down;
}

LinkChange LinkMonitor::on_reported(bus::LinkState reported) {
  // A reported down is believed only once an operation fails with it.
  if (up_ || reported != bus::LinkState::up) return LinkChange::none;
  reconnects_.fetch_add(1);
  up_ = true;
  state_.store(bus::LinkState::up);
  return LinkChange::came_up;
}

}  // namespace dh3::hand
