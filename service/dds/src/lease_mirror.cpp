#include "lease_mirror.hpp"

#include <chrono>

namespace dh3::dds {

msg::HandLease lease_sample(const std::string& service, const std::string& bus,
                            std::uint8_t can_id, const std::optional<HeldLease>& lease) {
  msg::HandLease sample;
  sample.service(service);
  sample.bus(bus);
  sample.can_id(can_id);
  if (lease) {
    sample.holder_id(lease->holder_id);
    sample.holder_shown(lease->holder);
    // Rounded up: a lease with under a millisecond left is still held.
    const auto left = std::chrono::ceil<std::chrono::milliseconds>(lease->left).count();
    sample.ttl_left_ms(static_cast<std::uint32_t>(std::max<std::int64_t>(left, 0)));
  }
  return sample;
}

void LeaseMirror::received(const std::string& writer, const msg::HandLease& sample,
                           TimePoint now) {
  if (sample.service() != service_ || sample.can_id() < limits::CAN_ID_MIN ||
      sample.can_id() > limits::CAN_ID_MAX || sample.bus().size() > limits::MAX_NAME_LENGTH) {
    return;
  }
  auto known = by_writer_.find(writer);
  if (known == by_writer_.end()) {
    if (by_writer_.size() >= kMaxWriters) return;
    known = by_writer_.emplace(writer, Hands{}).first;
  }
  const auto hand = std::make_pair(sample.bus(), static_cast<std::uint8_t>(sample.can_id()));
  if (sample.holder_id().empty() || sample.ttl_left_ms() == 0) {
    known->second.erase(hand);
    return;
  }
  known->second[hand] = {sample.holder_id(), sample.holder_shown(),
                         now + std::chrono::milliseconds(sample.ttl_left_ms())};
}

std::vector<HandedLease> LeaseMirror::held_by_writer(const std::string& writer,
                                                     TimePoint now) const {
  std::vector<HandedLease> held;
  const auto known = by_writer_.find(writer);
  if (known == by_writer_.end()) return held;
  for (const auto& [hand, entry] : known->second) {
    if (entry.expires <= now) continue;
    held.push_back({hand.first, hand.second, entry.holder_id, entry.holder, entry.expires - now});
  }
  return held;
}

}  // namespace dh3::dds
