#pragma once
// Loop thread only: the bus loop tells it what was sent and answered, and when.
// Pure: it is told the time; it reads no clock and sends nothing itself.
//
// The probe of CAN IDs 1-255 for hands nobody configured: one
// firmware-version read per ID, spaced (SchedulerOptions::probe_spacing) so
// that known hands keep the bus. A scan runs when one is requested, and on a
// bus that lists no hands at start and then every discovery_interval. A probe
// that gets no answer within the reply timeout found nothing. The scheduler
// sends the probes this class says are due and creates a driver for each
// hand that answers.

#include <bitset>
#include <cstdint>
#include <map>
#include <optional>
#include <vector>

#include "dh3/base/clock.hpp"
#include "dh3/hand/bus_scheduler.hpp"

namespace dh3::hand {

struct DiscoveryOptions {
  /// Scan by itself, at start and then every `interval` (a bus that lists no hands).
  bool periodic = false;
  /// 0: a periodic scan runs once.
  Duration interval = std::chrono::seconds(30);
  Duration probe_spacing = std::chrono::milliseconds(1);
  Duration reply_timeout = std::chrono::milliseconds(150);
};

/// What a pass's on_time() found.
enum class ScanTick : std::uint8_t {
  idle,      ///< no scan runs, none is due
  started,   ///< a periodic scan is due and has started
  probing,   ///< a scan runs: IDs to probe or answers to wait for
  complete,  ///< every ID probed, every probe answered or timed out: call finish()
};

class DiscoveryScan {
 public:
  DiscoveryScan(DiscoveryOptions options, TimePoint now);

  /// A hand with this ID is known (configured or found): it answers its own
  /// polls, so no scan probes it.
  void known(std::uint8_t can_id) { known_.set(can_id); }

  /// Someone asked for a scan: `done` hears its result. Starts one if none
  /// runs, and then returns true.
  bool request(ScanCompletion done, TimePoint now);
  /// Expires probes whose time ran out and starts a periodic scan when due
  /// (on an up link only).
  ScanTick on_time(TimePoint now, bool link_up);
  /// Ends the scan, if one runs: everyone who asked hears `found`.
  void finish(const std::vector<std::uint8_t>& found);
  [[nodiscard]] bool active() const { return scan_.has_value(); }

  /// The ID to probe at `now`, if one is due.
  [[nodiscard]] std::optional<std::uint8_t> due_probe(TimePoint now);
  /// The probe due_probe() returned left at `left` (`now`: the pass's time,
  /// from which the next probe is spaced). True if another may follow in
  /// the same pass (no probe spacing).
  bool probe_sent(TimePoint now, TimePoint left);
  /// No probe before `allowed` (the spacing after a frame to ID 0).
  void hold_until(TimePoint allowed);
  /// A firmware-version reply from `can_id`, which has no driver: when the
  /// probe it answers left, or nullopt if no probe to that ID waits.
  std::optional<TimePoint> answered(std::uint8_t can_id);

  /// The link is back: a periodic scan is due at once.
  void on_link_up(TimePoint now);
  /// When the scan next needs the loop: a probe due, a probe's deadline, or
  /// the next periodic scan.
  [[nodiscard]] std::optional<TimePoint> next_wakeup() const;

 private:
  struct Probe {
    TimePoint sent{};
    TimePoint deadline{};
  };
  struct Scan {
    std::vector<ScanCompletion> waiting;
    int next_id = 1;
    TimePoint next_probe_at{};
    std::map<std::uint8_t, Probe> pending;  ///< probed, not answered yet
  };

  DiscoveryOptions options_;
  std::bitset<256> known_;
  bool scanned_once_ = false;
  TimePoint next_periodic_at_{};
  std::optional<Scan> scan_;
};

}  // namespace dh3::hand
