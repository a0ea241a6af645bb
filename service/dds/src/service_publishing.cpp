// Publishing what the service knows: hand statuses, hand events and the
// service's info.

#include <algorithm>
#include <chrono>

#include "service_impl.hpp"

namespace dh3::dds {
using contract::TopicRole;
using eprosima::fastrtps::types::ReturnCode_t;

// ---------------------------------------------------------------------------
// Status, events, service info

Service::Impl::HandSlot& Service::Impl::slot_locked(BusRuntime& bus, std::uint8_t can_id) {
  auto& slot = bus.hands[can_id];
  if (!slot) slot = std::make_unique<HandSlot>();
  return *slot;
}

void Service::Impl::prepare_status_locked(std::uint16_t bus, std::uint8_t can_id, HandSlot& slot) {
  slot.sample.lease_holder(leases_.holder(HandKey{bus, can_id}));
  slot.sample.update_seq(++slot.update_seq);
  slot.sample.timestamp_ns(wall_clock_ns());
}

void Service::Impl::send_status_locked(std::uint16_t bus, std::uint8_t can_id, HandSlot& slot) {
  slot.held = false;
  slot.sent_at = clock_.now();
  if (status_writer_ == nullptr) return;  // DDS set-up failed or is gone
  std::lock_guard write_lock(status_write_mutex_);
  if (!status_writer_->write(&slot.sample)) {
    spdlog::warn("could not publish the status of {}", hand_text(buses_[bus]->name, can_id));
  }
}

void Service::Impl::write_status_locked(std::uint16_t bus, std::uint8_t can_id, HandSlot& slot) {
  prepare_status_locked(bus, can_id, slot);
  send_status_locked(bus, can_id, slot);
}

void Service::Impl::send_held_status(std::uint16_t bus_index, std::uint8_t can_id) {
  BusRuntime& bus = *buses_[bus_index];
  std::lock_guard lock(bus.status_mutex);
  HandSlot* slot = bus.hands[can_id].get();
  if (slot != nullptr && slot->held) send_status_locked(bus_index, can_id, *slot);
}

void Service::Impl::attach_status(msg::CommandReply& reply, std::uint16_t bus_index,
                                  std::uint8_t can_id) {
  BusRuntime& bus = *buses_[bus_index];
  std::lock_guard lock(bus.status_mutex);
  const HandSlot* slot = bus.hands[can_id].get();
  if (slot != nullptr && slot->written) reply.status(slot->sample);
}

std::uint64_t Service::Impl::wall_clock_ns_of(TimePoint time) const {
  if (time == TimePoint{}) return 0;  // never
  // The hand layer keeps steady time; samples say wall time, like timestamp_ns.
  const auto age = std::chrono::duration_cast<std::chrono::nanoseconds>(clock_.now() - time);
  return wall_clock_ns() - static_cast<std::uint64_t>(std::max<std::int64_t>(age.count(), 0));
}

void Service::Impl::republish_status(HandKey hand) {
  BusRuntime& bus = *buses_[hand.bus];
  std::lock_guard lock(bus.status_mutex);
  HandSlot& slot = slot_locked(bus, hand.can_id);
  // A hand's first status carries its lease holder anyway.
  if (slot.written) write_status_locked(hand.bus, hand.can_id, slot);
}

void Service::Impl::hold_republished_status(HandKey hand, msg::CommandReply& reply) {
  BusRuntime& bus = *buses_[hand.bus];
  std::lock_guard lock(bus.status_mutex);
  HandSlot& slot = slot_locked(bus, hand.can_id);
  // A hand's first status carries its lease holder anyway.
  if (!slot.written) return;
  prepare_status_locked(hand.bus, hand.can_id, slot);
  slot.held = true;
  reply.status(slot.sample);
}

void Service::Impl::on_state(std::uint16_t bus_index, const hand::HandState& state) {
  std::lock_guard lock(buses_[bus_index]->status_mutex);
  on_state_locked(bus_index, state, true);  // sent at the batch's end (on_batch_end)
}

void Service::Impl::on_fresh(std::uint16_t bus_index, const hand::HandState& state) {
  BusRuntime& bus = *buses_[bus_index];
  std::lock_guard lock(bus.status_mutex);
  const HandSlot* slot = bus.hands[state.can_id].get();
  // Only the read time is new: a watcher learns the hand is alive and its
  // values fresh from one sample per refresh; more would cost every watcher
  // of the domain a sample per idle read. A held sample goes out anyway.
  if (slot != nullptr && slot->written && !slot->held &&
      clock_.now() - slot->sent_at < options_.status_refresh) {
    return;
  }
  on_state_locked(bus_index, state, true);  // sent at the batch's end (on_batch_end)
}

void Service::Impl::on_state_locked(std::uint16_t bus_index, const hand::HandState& state,
                                    bool hold) {
  BusRuntime& bus = *buses_[bus_index];
  HandSlot& slot = slot_locked(bus, state.can_id);
  if (!std::exchange(slot.announced, true)) {
    spdlog::debug("found {}", hand_text(bus.name, state.can_id));
    publish_info();  // the roster lists it already
  }
  fill_status(slot.sample, state,
              StatusContext{options_.name, bus.name, {}, 0, 0, wall_clock_ns_of(state.read_at)});
  slot.written = true;
  prepare_status_locked(bus_index, state.can_id, slot);  // lease holder, sequence and time
  if (hold) {
    slot.held = true;
  } else {
    send_status_locked(bus_index, state.can_id, slot);
  }
}

void Service::Impl::on_event(std::uint16_t bus_index, const hand::HandEvent& event) {
  BusRuntime& bus = *buses_[bus_index];
  // The hand layer logs events itself; this line only adds the service's view.
  spdlog::debug("event of {}: {}{}{}", hand_text(bus.name, event.can_id),
                hand::to_string(event.kind), event.message.empty() ? "" : ": ", event.message);
  if (event_writer_ == nullptr) return;
  std::lock_guard lock(bus.status_mutex);
  // The status that explains the event goes first, as a subscriber expects.
  if (HandSlot* slot = bus.hands[event.can_id].get(); slot != nullptr && slot->held) {
    send_status_locked(bus_index, event.can_id, *slot);
  }
  fill_event(bus.event_sample, event, options_.name, bus.name,
             directory_.hand_name(bus_index, event.can_id), ++event_seq_, wall_clock_ns());
  if (!event_writer_->write(&bus.event_sample)) {
    spdlog::warn("could not publish a {} event of {}", hand::to_string(event.kind),
                 hand_text(bus.name, event.can_id));
  }
}

void Service::Impl::on_link(std::uint16_t bus_index, bus::LinkState state) {
  const bool up = state == bus::LinkState::up;
  BusRuntime& bus = *buses_[bus_index];
  if (bus.link_up.exchange(up) == up) return;
  // The bus and hand layers log the link change; here it only goes to the service info.
  spdlog::debug("bus '{}' ({}) is {}: service info republished", bus.name, bus.spec,
                up ? "up" : "down");
  publish_info();
}

void Service::Impl::publish_info() {
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
