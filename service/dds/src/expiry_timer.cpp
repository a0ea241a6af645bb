// The timer thread: wait for a deadline or a wake-up, sweep, look again.

#include "expiry_timer.hpp"

namespace dh3::dds {

ExpiryTimer::ExpiryTimer(NextDue next_due, Sweep sweep)
    : next_due_(std::move(next_due)), sweep_(std::move(sweep)) {}

ExpiryTimer::~ExpiryTimer() {
  stop();
}

void ExpiryTimer::start() {
  if (thread_.joinable()) return;
  thread_ = std::thread([this] { loop(); });
}

void ExpiryTimer::wake() {
  {
    std::lock_guard lock(mutex_);
    ++generation_;
  }
  cv_.notify_all();
}

void ExpiryTimer::stop() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void ExpiryTimer::loop() {
  std::unique_lock lock(mutex_);
  while (!stop_) {
    const std::uint64_t seen = generation_;
    const auto woken = [&] { return stop_ || generation_ != seen; };
    if (const auto next = next_due_()) {
      // The deadlines' clock is the steady clock in a running service.
      cv_.wait_until(lock, *next, woken);
    } else {
      cv_.wait(lock, woken);
    }
    if (stop_) break;
    lock.unlock();
    sweep_();
    lock.lock();
  }
}

}  // namespace dh3::dds
