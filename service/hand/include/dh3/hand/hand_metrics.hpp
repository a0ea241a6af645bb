#pragma once
// What the hand layer counts for monitoring, as a snapshot any thread may take
// (BusScheduler::metrics()). Counting happens on the loop thread (and, for
// commands refused at once, on the submitting thread) with relaxed atomics, so
// a reader never stops the loop. The layers above name and export it.

#include <array>
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "dh3/base/clock.hpp"
#include "dh3/bus/bus.hpp"
#include "dh3/hand/hand_types.hpp"
#include "dh3/hand/latency_histogram.hpp"
#include "dh3/protocol/registers.hpp"

namespace dh3::hand {

/// Upper bounds of the round-trip histogram (frame sent to matching reply):
/// a reply on an idle CAN line comes in about a millisecond and the reply
/// deadline is 150 ms by default; administrative writes, which answer after
/// storing, land above the last bound.
inline constexpr std::array<Duration, 11> kRoundTripBuckets{
    std::chrono::microseconds(500), std::chrono::milliseconds(1),   std::chrono::milliseconds(2),
    std::chrono::milliseconds(5),   std::chrono::milliseconds(10),  std::chrono::milliseconds(20),
    std::chrono::milliseconds(50),  std::chrono::milliseconds(100), std::chrono::milliseconds(200),
    std::chrono::milliseconds(500), std::chrono::seconds(1)};

/// The nominal size of the frames the bus carries (8 data bytes, 11-bit ID,
/// no stuff bits): what line-load figures assume. Stuffing adds up to 24 bits,
/// so the true load is up to a fifth higher.
inline constexpr double kBitsPerFrame = 111.0;

/// How many commands of one type ended with one result.
struct CommandTally {
  CommandKind kind = CommandKind::read_register;
  /// For write_register: the CAN ID, baud-rate or init-feedback register (the
  /// contract's SET_CAN_ID, SET_BAUD_RATE, ENABLE_INIT_FEEDBACK); other writes
  /// are counted together with a default register.
  protocol::Register reg{};
  std::optional<CommandError> error;  ///< nullopt: OK
  std::uint64_t count = 0;
};

struct RoundTripHistogram {
  /// Observations per bucket of kRoundTripBuckets (not cumulative); the last
  /// element counts those above the largest bound.
  std::array<std::uint64_t, kRoundTripBuckets.size() + 1> counts{};
  double sum_seconds = 0.0;
  [[nodiscard]] std::uint64_t total() const;
};

struct HandMetrics {
  std::uint8_t can_id = 0;
  std::string name;
  /// nullopt for ID 0, which addresses whichever hand is there.
  std::optional<bool> online;
  std::vector<CommandTally> commands;  ///< only the non-zero tallies
  std::uint64_t timeouts = 0;          ///< frames unanswered within their deadline
  std::uint64_t retries = 0;           ///< frames sent again after a timeout
  RoundTripHistogram round_trip;
};

/// Totals of one bus since the scheduler started.
struct SchedulerCounters {
  std::uint64_t frames_sent = 0;
  std::uint64_t frames_received = 0;
  std::uint64_t unexpected_frames = 0;
  /// The sums of every hand's retries and timeouts (HandMetrics), which are
  /// the only ones counted.
  std::uint64_t retries = 0;
  std::uint64_t timeouts = 0;
  /// Sends and receives the backend refused on a live link (io_error,
  /// frame_invalid); a link going down is counted as reconnects instead.
  std::uint64_t bus_errors = 0;
  /// Link down -> up transitions (a first connection made after start counts).
  std::uint64_t reconnects = 0;
};

/// How long things take on one bus (LatencyHistogram snapshots, every hand
/// of the bus together; observed on the loop thread).
struct BusLatency {
  /// A command from its submission (the request taken) to its first frame
  /// handed to the bus; commands that end without a frame are not counted.
  LatencySnapshot command_to_frame;
  /// Any frame to a hand (command or poll) to its matching reply (the echo).
  LatencySnapshot frame_to_reply;
  /// A command from its submission to its result handed back (any result).
  LatencySnapshot command_to_reply;
  /// Each status sample when it is published (a changed state, or the same
  /// one read again): how long since the hand's reply it reflects.
  LatencySnapshot sample_age;
};

struct BusMetrics {
  std::string bus;
  bool link_up = false;
  SchedulerCounters counters;
  std::uint32_t bit_rate = 0;  ///< 0: the backend does not know its line rate
  /// Frames sent and received per second over the last few seconds.
  double recent_frames_per_second = 0.0;
  /// recent_frames_per_second x kBitsPerFrame as percent of bit_rate; nullopt
  /// when the bit rate is unknown.
  std::optional<double> line_load_percent;
  /// The backend's own view of the controller (error frames, kernel drops).
  bus::BusDiagnostics diagnostics;
  std::vector<HandMetrics> hands;  ///< by CAN ID
  BusLatency latency;
};

}  // namespace dh3::hand
