#pragma once
// A standby service's watch over the cell's buses: each bus opened behind a
// StandbyBus (it hears every frame, sends none), one loop per bus reading what
// the active service and the hands say into ObservedHands (the warm state) and
// a BusFence (is anybody still driving this bus?). take_buses() hands the
// buses, promoted, to the service that takes over.
//
// Threading: start() and take_buses() from one thread; states(), fences_clear()
// and figures from any thread.

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "dh3/base/clock.hpp"
#include "dh3/bus/standby_bus.hpp"
#include "dh3/dds/service.hpp"
#include "dh3/hand/bus_fence.hpp"
#include "dh3/hand/observed_hands.hpp"

namespace dh3::app {

class StandbyWatch {
 public:
  /// Takes the opened buses; each one's bus is wrapped in a StandbyBus.
  /// `quiet`: how long a bus must carry no request before it counts as free
  /// (BusFence).
  StandbyWatch(std::vector<dds::BusSetup> buses, Duration quiet, const Clock& clock);
  ~StandbyWatch();
  StandbyWatch(const StandbyWatch&) = delete;
  StandbyWatch& operator=(const StandbyWatch&) = delete;

  /// Starts one loop per bus.
  void start();
  /// Ends the loops, promotes every bus and hands the setups over (once).
  [[nodiscard]] std::vector<dds::BusSetup> take_buses();

  /// Every bus's hands as the frames seen tell them, bus by bus.
  [[nodiscard]] std::vector<std::vector<hand::HandState>> states() const;
  /// No bus carried a request in its quiet time before `now`.
  [[nodiscard]] bool fences_clear(TimePoint now) const;
  /// The last time a read of every bus found it silent: the bus carried
  /// requests once, then none for its quiet time, and the read found
  /// nothing unread. nullopt while a bus is not silent (busy, down, or never
  /// driven: a bus nobody polls says nothing of who drives it).
  [[nodiscard]] std::optional<TimePoint> silent_at() const;
  /// The names of the buses that did.
  [[nodiscard]] std::vector<std::string> busy_buses(TimePoint now) const;
  /// Requests of another service seen, over every bus.
  [[nodiscard]] std::uint64_t requests_seen() const;

 private:
  struct Watched {
    dds::BusSetup setup;
    bus::StandbyBus* gate = nullptr;  ///< setup.bus, as the StandbyBus it is
    mutable std::mutex mutex;         ///< guards hands and fence
    hand::ObservedHands hands;
    hand::BusFence fence;
    std::optional<TimePoint> silent_read_at;  ///< see silent_at()
    std::thread loop;
    Watched(dds::BusSetup opened, Duration quiet, TimePoint now);
  };

  void watch(Watched& watched);

  const Clock& clock_;
  std::vector<std::unique_ptr<Watched>> buses_;
  std::atomic<bool> running_{false};
};

}  // namespace dh3::app
