// Hand statuses, hand events and the service info, as the bus loops report
// them and as requests and lease changes need them again.

#include "status_publisher.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <utility>

#include "conversions.hpp"

namespace dh3::dds {

StatusPublisher::StatusPublisher(const ServiceOptions& options, const Clock& clock,
                                 const LeaseTable& leases, const HandDirectory& directory)
    : options_(options),
      clock_(clock),
      leases_(leases),
      directory_(directory),
      started_ns_(wall_clock_ns()) {}

std::uint16_t StatusPublisher::add_bus(std::string name, std::string spec,
                                       const std::vector<std::uint8_t>& configured) {
  auto bus = std::make_unique<BusStatus>();
  bus->name = std::move(name);
  bus->spec = std::move(spec);
  // Configured hands are in the service info from the start: not news (on_state).
  for (const std::uint8_t can_id : configured) slot_locked(*bus, can_id).announced = true;
  buses_.push_back(std::move(bus));
  return static_cast<std::uint16_t>(buses_.size() - 1);
}

void StatusPublisher::set_writers(eprosima::fastdds::dds::DataWriter* status,
                                  eprosima::fastdds::dds::DataWriter* event,
                                  eprosima::fastdds::dds::DataWriter* info) {
  status_writer_ = status;
  event_writer_ = event;
  info_writer_ = info;
}

StatusPublisher::HandSlot& StatusPublisher::slot_locked(BusStatus& bus, std::uint8_t can_id) {
  auto& slot = bus.hands[can_id];
  if (!slot) slot = std::make_unique<HandSlot>();
  return *slot;
}

void StatusPublisher::prepare_locked(std::uint16_t bus, std::uint8_t can_id, HandSlot& slot) {
  slot.sample.lease_holder(leases_.holder(HandKey{bus, can_id}));
  slot.sample.update_seq(++slot.update_seq);
  slot.sample.timestamp_ns(wall_clock_ns());
}

void StatusPublisher::send_locked(std::uint16_t bus, std::uint8_t can_id, HandSlot& slot) {
  slot.held = false;
  if (status_writer_ == nullptr) return;  // DDS set-up failed or is gone
  std::lock_guard write_lock(status_write_mutex_);
  if (!status_writer_->write(&slot.sample)) {
    spdlog::warn("could not publish the status of {}", hand_text(buses_[bus]->name, can_id));
  }
}

void StatusPublisher::send_held(std::uint16_t bus_index, std::uint8_t can_id) {
  BusStatus& bus = *buses_[bus_index];
  std::lock_guard lock(bus.mutex);
  HandSlot* slot = bus.hands[can_id].get();
  if (slot != nullptr && slot->held) send_locked(bus_index, can_id, *slot);
}

void StatusPublisher::attach_to(msg::CommandReply& reply, std::uint16_t bus_index,
                                std::uint8_t can_id) {
  BusStatus& bus = *buses_[bus_index];
  std::lock_guard lock(bus.mutex);
  const HandSlot* slot = bus.hands[can_id].get();
  if (slot != nullptr && slot->written) reply.status(slot->sample);
}

std::uint64_t StatusPublisher::wall_clock_ns_of(TimePoint time) const {
  if (time == TimePoint{}) return 0;  // never
  // The hand layer keeps steady time; samples say wall time, like timestamp_ns.
  const auto age = std::chrono::duration_cast<std::chrono::nanoseconds>(clock_.now() - time);
  return wall_clock_ns() - static_cast<std::uint64_t>(std::max<std::int64_t>(age.count(), 0));
}

void StatusPublisher::republish(HandKey hand) {
  BusStatus& bus = *buses_[hand.bus];
  std::lock_guard lock(bus.mutex);
  HandSlot& slot = slot_locked(bus, hand.can_id);
  // A hand's first status carries its lease holder anyway.
  if (!slot.written) return;
  prepare_locked(hand.bus, hand.can_id, slot);
  send_locked(hand.bus, hand.can_id, slot);
}

void StatusPublisher::hold_republished(HandKey hand, msg::CommandReply& reply) {
  BusStatus& bus = *buses_[hand.bus];
  std::lock_guard lock(bus.mutex);
  HandSlot& slot = slot_locked(bus, hand.can_id);
  // A hand's first status carries its lease holder anyway.
  if (!slot.written) return;
  prepare_locked(hand.bus, hand.can_id, slot);
  slot.held = true;
  reply.status(slot.sample);
}

void StatusPublisher::on_state(std::uint16_t bus_index, const hand::HandState& state) {
  std::lock_guard lock(buses_[bus_index]->mutex);
  on_state_locked(bus_index, state, true);  // sent at the batch's end (on_batch_end)
}

void StatusPublisher::on_fresh(std::uint16_t bus_index, const hand::HandState& state) {
  BusStatus& bus = *buses_[bus_index];
  std::lock_guard lock(bus.mutex);
  const HandSlot* slot = bus.hands[state.can_id].get();
  // Only the read time is new: a watcher learns the hand is alive and its
  // values fresh from one sample per refresh; more would cost every watcher
  // of the domain a sample per idle read. A held sample goes out anyway.
  // Counted from the read time published, not from the last sample sent: a
  // lease's sample in between carries the old read time, and waiting a whole
  // refresh after it would show a watcher values up to two refreshes old.
  if (slot != nullptr && slot->written && !slot->held &&
      clock_.now() - slot->state_at < options_.status_refresh) {
    return;
  }
  on_state_locked(bus_index, state, true);  // sent at the batch's end (on_batch_end)
}

void StatusPublisher::publish_first(std::uint16_t bus_index,
                                    const std::vector<hand::HandState>& states) {
  BusStatus& bus = *buses_[bus_index];
  for (const hand::HandState& state : states) {
    std::lock_guard lock(bus.mutex);
    if (slot_locked(bus, state.can_id).update_seq == 0) on_state_locked(bus_index, state, false);
  }
}

void StatusPublisher::on_state_locked(std::uint16_t bus_index, const hand::HandState& state,
                                      bool hold) {
  BusStatus& bus = *buses_[bus_index];
  HandSlot& slot = slot_locked(bus, state.can_id);
  if (!std::exchange(slot.announced, true)) {
    spdlog::debug("found {}", hand_text(bus.name, state.can_id));
    publish_info();  // the roster lists it already
  }
  fill_status(slot.sample, state,
              StatusContext{options_.name, bus.name, {}, 0, 0, wall_clock_ns_of(state.read_at)});
  slot.written = true;
  slot.state_at = clock_.now();
  prepare_locked(bus_index, state.can_id, slot);  // lease holder, sequence and time
  if (hold) {
    slot.held = true;
  } else {
    send_locked(bus_index, state.can_id, slot);
  }
}

void StatusPublisher::publish_all_offline() {
  for (std::size_t i = 0; i < buses_.size(); ++i) {
    BusStatus& bus = *buses_[i];
    std::lock_guard lock(bus.mutex);
    for (std::size_t id = 0; id < bus.hands.size(); ++id) {
      HandSlot* slot = bus.hands[id].get();
      if (slot && slot->written && slot->sample.online()) {
        slot->sample.online(false);
        const auto bus_index = static_cast<std::uint16_t>(i);
        const auto can_id = static_cast<std::uint8_t>(id);
        prepare_locked(bus_index, can_id, *slot);
        send_locked(bus_index, can_id, *slot);
      }
    }
  }
}

void StatusPublisher::on_event(std::uint16_t bus_index, const hand::HandEvent& event) {
  BusStatus& bus = *buses_[bus_index];
  // The hand layer logs events itself; this line only adds the service's view.
  spdlog::debug("event of {}: {}{}{}", hand_text(bus.name, event.can_id),
                hand::to_string(event.kind), event.message.empty() ? "" : ": ", event.message);
  if (event_writer_ == nullptr) return;
  std::lock_guard lock(bus.mutex);
  // The status that explains the event goes first, as a subscriber expects.
  if (HandSlot* slot = bus.hands[event.can_id].get(); slot != nullptr && slot->held) {
    send_locked(bus_index, event.can_id, *slot);
  }
  fill_event(bus.event_sample, event, options_.name, bus.name,
             directory_.hand_name(bus_index, event.can_id), ++event_seq_, wall_clock_ns());
  if (!event_writer_->write(&bus.event_sample)) {
    spdlog::warn("could not publish a {} event of {}", hand::to_string(event.kind),
                 hand_text(bus.name, event.can_id));
  }
}

void StatusPublisher::on_link(std::uint16_t bus_index, bus::LinkState state) {
  const bool up = state == bus::LinkState::up;
  BusStatus& bus = *buses_[bus_index];
  if (bus.link_up.exchange(up) == up) return;
  // The bus and hand layers log the link change; here it only goes to the service info.
  spdlog::debug("bus '{}' ({}) is {}: service info republished", bus.name, bus.spec,
                up ? "up" : "down");
  publish_info();
}

void StatusPublisher::publish_info() {
  if (info_writer_ == nullptr) return;
  std::lock_guard lock(info_mutex_);
  msg::ServiceInfo info;
  info.service(options_.name);
  info.version(options_.version);
  info.host(options_.host);
  info.admin_allowed(options_.allow_admin);
  info.started_ns(started_ns_);
  for (std::size_t i = 0; i < buses_.size(); ++i) {
    msg::BusInfo bus;
    bus.name(buses_[i]->name);
    bus.spec(buses_[i]->spec);
    bus.link_up(buses_[i]->link_up.load());
    for (const auto& hand : directory_.hands(static_cast<std::uint16_t>(i))) {
      msg::HandInfo entry;
      entry.can_id(hand.can_id);
      entry.name(hand.name);
      bus.hands().push_back(std::move(entry));
    }
    info.buses().push_back(std::move(bus));
  }
  if (!info_writer_->write(&info)) {
    spdlog::warn("could not publish the service info");
  }
}

}  // namespace dh3::dds
