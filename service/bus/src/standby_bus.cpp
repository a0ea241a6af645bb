#include "dh3/bus/standby_bus.hpp"

namespace dh3::bus {

StandbyBus::StandbyBus(std::unique_ptr<Bus> inner) : inner_(std::move(inner)) {}

Result<void, BusError> StandbyBus::send(const CanFrame& frame) {
  if (!promoted()) {
    refused_.fetch_add(1, std::memory_order_relaxed);
    return fail(BusError::not_permitted);
  }
  return inner_->send(frame);
}

Result<std::size_t, BusError> StandbyBus::send_burst(std::span<const CanFrame> frames) {
  if (!promoted()) {
    refused_.fetch_add(frames.size(), std::memory_order_relaxed);
    return fail(BusError::not_permitted);
  }
  return inner_->send_burst(frames);
}

}  // namespace dh3::bus
