#pragma once
// The service's timer thread: it sleeps until the earliest deadline that
// `next_due` names (leases, held replies), or until woken, then runs `sweep`.
//
// Threading: start()/stop() from the owner, wake() from any thread; `next_due`
// runs on the timer thread under its mutex, `sweep` without it. Knows no DDS.

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>

#include "dh3/base/clock.hpp"

namespace dh3::dds {

class ExpiryTimer {
 public:
  /// The earliest deadline, on the steady clock; nullopt if none.
  using NextDue = std::function<std::optional<TimePoint>()>;
  using Sweep = std::function<void()>;

  ExpiryTimer(NextDue next_due, Sweep sweep);
  ~ExpiryTimer();
  ExpiryTimer(const ExpiryTimer&) = delete;
  ExpiryTimer& operator=(const ExpiryTimer&) = delete;

  void start();
  /// A deadline may have moved earlier: look again (then sweep).
  void wake();
  /// Ends and joins the thread; no sweep starts after it returns. Idempotent.
  void stop();

 private:
  void loop();

  NextDue next_due_;
  Sweep sweep_;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::uint64_t generation_ = 0;  ///< under mutex_: counts wake() calls
  bool stop_ = false;             ///< under mutex_
  std::thread thread_;
};

}  // namespace dh3::dds
