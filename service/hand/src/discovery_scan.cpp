#include "discovery_scan.hpp"

#include <algorithm>

namespace dh3::hand {

namespace {
constexpr int kLastId = 255;
}  // namespace

DiscoveryScan::DiscoveryScan(DiscoveryOptions options, TimePoint now)
    : options_(options), next_periodic_at_(now) {}

bool DiscoveryScan::request(ScanCompletion done, TimePoint now) {
  const bool starts = !scan_;
  if (starts) scan_.emplace().next_probe_at = now;
  scan_->waiting.push_back(std::move(done));
  return starts;
}

ScanTick DiscoveryScan::on_time(TimePoint now, bool link_up) {
  if (!scan_) {
    if (options_.periodic && link_up && now >= next_periodic_at_ &&
        (options_.interval > Duration::zero() || !scanned_once_)) {
      scan_.emplace().next_probe_at = now;
      return ScanTick::started;
    }
    return ScanTick::idle;
  }
  std::erase_if(scan_->pending, [&](const auto& entry) { return now >= entry.second.deadline; });
  if (scan_->next_id <= kLastId || !scan_->pending.empty()) return ScanTick::probing;
  scanned_once_ = true;
  next_periodic_at_ = now + options_.interval;
  return ScanTick::complete;
}

void DiscoveryScan::finish(const std::vector<std::uint8_t>& found) {
  if (!scan_) return;
  auto waiting = std::move(scan_->waiting);
  scan_.reset();
  for (ScanCompletion& done : waiting) done(found);
}

std::optional<std::uint8_t> DiscoveryScan::due_probe(TimePoint now) {
  if (!scan_ || now < scan_->next_probe_at) return std::nullopt;
  while (scan_->next_id <= kLastId && known_.test(static_cast<std::size_t>(scan_->next_id))) {
    ++scan_->next_id;
  }
  if (scan_->next_id > kLastId) return std::nullopt;
  return static_cast<std::uint8_t>(scan_->next_id);
}

bool DiscoveryScan::probe_sent(TimePoint now, TimePoint left) {
  if (!scan_ || scan_->next_id > kLastId) return false;
  const auto id = static_cast<std::uint8_t>(scan_->next_id);
  scan_->pending[id] = Probe{left, left + options_.reply_timeout};
  ++scan_->next_id;
  scan_->next_probe_at = now + options_.probe_spacing;
  return options_.probe_spacing <= Duration::zero();
}

void DiscoveryScan::hold_until(TimePoint allowed) {
  if (scan_) scan_->next_probe_at = std::max(scan_->next_probe_at, allowed);
}

std::optional<TimePoint> DiscoveryScan::answered(std::uint8_t can_id) {
  if (!scan_) return std::nullopt;
  const auto probe = scan_->pending.find(can_id);
  if (probe == scan_->pending.end()) return std::nullopt;
  const TimePoint sent = probe->second.sent;
  scan_->pending.erase(probe);
  return sent;
}

void DiscoveryScan::on_link_up(TimePoint now) {
  if (options_.periodic) next_periodic_at_ = now;
}

std::optional<TimePoint> DiscoveryScan::next_wakeup() const {
  std::optional<TimePoint> earliest;
  auto consider = [&](TimePoint t) {
    if (!earliest || t < *earliest) earliest = t;
  };
  if (scan_) {
    if (scan_->next_id <= kLastId) consider(scan_->next_probe_at);
    for (const auto& [id, probe] : scan_->pending) consider(probe.deadline);
  } else if (options_.periodic && options_.interval > Duration::zero()) {
    consider(next_periodic_at_);
  }
  return earliest;
}

}  // namespace dh3::hand
