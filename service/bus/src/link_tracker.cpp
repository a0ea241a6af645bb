#include "dh3/bus/link_tracker.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <utility>

namespace dh3::bus {
namespace {

long long to_ms(Duration d) {
  return static_cast<long long>(std::chrono::duration_cast<std::chrono::milliseconds>(d).count());
}

}  // namespace

LinkTracker::LinkTracker(std::string name, ReconnectOptions options)
    : name_(std::move(name)), options_(options) {
  options_.initial_backoff = std::max(options_.initial_backoff, Duration::zero());
  options_.max_backoff = std::max(options_.max_backoff, options_.initial_backoff);
  next_delay_ = options_.initial_backoff;
}

void LinkTracker::mark_up() {
  if (state() == LinkState::up) return;
  if (failure_logged_) {
    spdlog::info("{}: link up again (after {} attempts)", name_, attempts_);
  } else {
    spdlog::info("{}: link up", name_);
  }
  state_.store(LinkState::up, std::memory_order_relaxed);
  ever_up_ = true;
  failure_logged_ = false;
  next_delay_ = options_.initial_backoff;
}

void LinkTracker::mark_down(std::string_view reason, TimePoint now) {
  const bool was_up = state() == LinkState::up;
  const Duration delay = next_delay_;
  next_attempt_at_ = now + delay;
  next_delay_ = std::min(next_delay_ * 2, options_.max_backoff);
  state_.store(LinkState::down, std::memory_order_relaxed);
  if (was_up) {
    ++drops_;
    spdlog::warn("{}: link down: {}; reconnecting (first retry in {} ms, backoff up to {} ms)",
                 name_, reason, to_ms(delay), to_ms(options_.max_backoff));
    failure_logged_ = true;
  } else if (!failure_logged_) {
    spdlog::warn("{}: cannot {}: {}; retrying (backoff {} ms doubling up to {} ms)", name_,
                 ever_up_ ? "reconnect" : "open link", reason, to_ms(delay),
                 to_ms(options_.max_backoff));
    failure_logged_ = true;
  } else {
    spdlog::debug("{}: attempt {} failed: {}; next in {} ms", name_, attempts_, reason,
                  to_ms(delay));
  }
}

}  // namespace dh3::bus
