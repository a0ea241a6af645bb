#pragma once
// One scheduler per bus: owns the Bus, one driver per hand on it, and the loop
// that sends, matches replies, paces, polls status, times out and detects
// events. Many hands share a bus fairly; every command ends in one result.
//
// Threading: submit(), request_scan(), state(), roster(), counters() and
// metrics() are safe from any thread.
// Everything else happens on the loop: either the scheduler's own thread
// (start()/stop()) or, in tests, whoever calls step(). Completions and observer
// callbacks run on the loop thread and must not block.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "dh3/base/clock.hpp"
#include "dh3/bus/bus.hpp"
#include "dh3/hand/hand_metrics.hpp"
#include "dh3/hand/hand_roster.hpp"
#include "dh3/hand/hand_types.hpp"

namespace dh3::hand {

/// Tuning of one bus. Defaults follow the document (20 ms between commands).
struct SchedulerOptions {
  /// Minimum time between two frames to the same hand (docs/protocol-notes.md reading 9).
  Duration command_interval = std::chrono::milliseconds(20);
  /// Added to command_interval when pacing, for a path that may delay one frame
  /// more than the next (a transfer box behind TCP or a serial line): the hand
  /// then still sees command_interval between them. 0 on SocketCAN and sim.
  Duration interval_margin{};
  /// What the scheduler keeps between two frames to one hand.
  [[nodiscard]] Duration frame_spacing() const { return command_interval + interval_margin; }
  /// Status polling by what can change (poll_policy.hpp): the status register
  /// that shows the change a hand waits for (the grip status of fingers that
  /// hold an object or move, the rotation status while rotating) is read every
  /// poll_interval_watch, and then nothing else is polled; the registers of an
  /// initializing hand every poll_interval_moving; a hand at rest that holds
  /// nothing reads all five every poll_interval_idle. Never closer than
  /// command_interval, and within the line budget.
  Duration poll_interval_watch = std::chrono::milliseconds(20);
  Duration poll_interval_moving = std::chrono::milliseconds(50);
  Duration poll_interval_idle = std::chrono::milliseconds(500);
  /// While fingers move (rotation rotates), their position (the rotation) is
  /// read this often too, so status samples show the motion under way; zero:
  /// only once it ended. Such a read delays an event that falls due in its
  /// frame by one frame (BENCHMARKS.md section 7).
  Duration poll_interval_position_moving = std::chrono::milliseconds(200);
  /// Deadline for one frame's reply before it is re-sent or fails.
  Duration reply_timeout = std::chrono::milliseconds(150);
  /// Deadline for CAN ID and baud-rate writes, which reply after storing (reading 6).
  Duration admin_reply_timeout = std::chrono::seconds(3);
  /// Re-sends of reads and idempotent writes after a timeout.
  int max_retries = 2;
  /// Consecutive timeouts after which a hand is offline.
  int offline_after_timeouts = 3;
  /// How often an offline hand is probed to see if it is back.
  Duration offline_probe_interval = std::chrono::seconds(1);
  /// Initialization must finish within this.
  Duration init_timeout = std::chrono::seconds(15);
  /// Grasp and release must end (caught / arrived) within this.
  Duration motion_timeout = std::chrono::seconds(10);
  /// Commands waiting per hand; more get BUSY.
  std::size_t queue_capacity = 16;
  /// When the bus lists no hands, probe IDs 1-255 at start and then this often
  /// (0 disables the repeat). A requested scan runs at any time.
  Duration discovery_interval = std::chrono::seconds(30);
  /// Gap between two discovery probes (one firmware-version read per ID), so a
  /// full 1-255 probe takes about 255 x this and leaves the bus to known hands.
  Duration probe_spacing = std::chrono::milliseconds(1);
  /// On a bus that knows its bit rate (Bus::bit_rate() > 0), the share of the
  /// line the scheduler offers at most: requests are spaced so that a request
  /// and its reply (2 frames of up to 135 bits) fit this share. On a CAN line,
  /// arbitration lets the lowest ID win, so a line asked for more than it
  /// carries starves the highest IDs; never asking for more keeps it fair.
  /// 0 disables the limit.
  double max_line_load = 0.8;
  /// Administrative registers (CAN ID, baud rate) may be written.
  bool allow_admin = false;
};

/// Receives what happens on the bus. Called on the loop thread.
class HandObserver {
 public:
  virtual ~HandObserver() = default;
  virtual void on_state(const HandState& state) = 0;
  /// The hand answered again and the published values still stand: `state` is
  /// the published state with a newer read_at. At most once per
  /// poll_interval_idle per hand, so that who shows the state can show how
  /// fresh it is without a sample on every poll.
  virtual void on_fresh(const HandState& /*state*/) {}
  virtual void on_event(const HandEvent& event) = 0;
  /// Ends one hand's batch: a state (on_state or on_fresh), then that hand's
  /// events, then the completions of its commands that the same pass ended,
  /// and then this. An observer may hold the state back until here: the
  /// service answers the commands first and publishes the state after.
  virtual void on_batch_end(std::uint8_t /*can_id*/) {}
  virtual void on_link(bus::LinkState state) = 0;
};

using Completion = std::function<void(const CommandResult&)>;
using ScanCompletion = std::function<void(const std::vector<std::uint8_t>& found)>;

class BusScheduler {
 public:
  /// `hands` empty: discover hands by probing (SchedulerOptions::discovery_interval).
  BusScheduler(std::string bus_name, std::unique_ptr<bus::Bus> bus, std::vector<HandConfig> hands,
               SchedulerOptions options, const Clock& clock, HandObserver& observer);
  ~BusScheduler();
  BusScheduler(const BusScheduler&) = delete;
  BusScheduler& operator=(const BusScheduler&) = delete;

  /// Queues a command for a hand. Validation errors, unknown hands and a full
  /// queue complete at once (on the caller's thread); everything else completes
  /// on the loop thread. Exactly one completion per call.
  void submit(std::uint8_t can_id, Command command, Completion done);

  /// Probes IDs 1-255 now and reports the IDs that answered.
  void request_scan(ScanCompletion done);

  /// Every known hand's last published state (the drivers own the live state
  /// on the loop; this is the copy they publish to the roster).
  [[nodiscard]] std::vector<HandState> state() const;
  /// The bus's hands, configured and discovered, and their published states.
  [[nodiscard]] const HandRoster& roster() const;
  [[nodiscard]] SchedulerCounters counters() const;
  /// The bus's counters, its recent load and every known hand's counters
  /// (hand_metrics.hpp); cheap enough for every scrape of a metrics endpoint.
  [[nodiscard]] BusMetrics metrics() const;
  [[nodiscard]] const std::string& name() const;
  [[nodiscard]] bus::LinkState link_state() const;

  /// Starts the hands from what a standby saw on the bus (ObservedHands's
  /// states, by CAN ID; hands not configured are left alone) and publishes
  /// them. Before start().
  void warm(const std::vector<HandState>& seen);

  /// Runs the loop on its own thread until stop(). stop() ends pending
  /// commands with CANCELLED and reports every hand offline.
  void start();
  void stop();

  /// One pass of the loop at clock.now() without waiting: receive what is
  /// there, match, time out, send what is due. For tests with a FakeClock.
  void step();
  /// When the loop next needs to run (earliest deadline or due send).
  [[nodiscard]] TimePoint next_wakeup() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dh3::hand
