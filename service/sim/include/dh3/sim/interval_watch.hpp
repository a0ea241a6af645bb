#pragma once
// The protocol document's "recommended interval between two commands is at
// least 20 ms", checked where a real hand would notice it: on the frames it
// receives. dh3-sim's --min-interval-ms turns it on for either transport.
//
// Per hand: a frame to a hand that comes sooner than the minimum after the
// previous frame to the same hand is a violation, logged (one warning each) and
// counted. A frame to ID 0 reaches every hand on the line (each hand's
// controller accepts its own ID and 0, docs/protocol-notes.md reading 10), so it counts for
// every hand present. Frames to IDs without a hand count for nobody, and so do
// frames no hand takes as a command (a register the document does not have, or
// a reserve byte other than 00): another node's traffic on a shared CAN line is
// not the service's to pace, and a hand does not act on it.
//
// Times are durations since an epoch the caller keeps fixed: the kernel's
// receive timestamp on CAN (CLOCK_REALTIME), the steady clock's read time on
// TCP. A muted hand counts too: the check judges the sender, who cannot know.
// A time earlier than the previous one (the real-time clock was stepped
// back) is no violation; it restarts that hand's measurement.

#include <array>
#include <cstdint>
#include <optional>

#include "dh3/base/clock.hpp"
#include "dh3/protocol/codec.hpp"

namespace dh3::sim {

class IntervalWatch {
 public:
  /// zero: the check is off and note() counts nothing.
  explicit IntervalWatch(Duration minimum = Duration::zero()) : minimum_(minimum) {}

  [[nodiscard]] bool enabled() const { return minimum_ > Duration::zero(); }
  [[nodiscard]] Duration minimum() const { return minimum_; }

  /// Notes `frame`, received at `at`, as a frame to hand `hand_id` (for a frame
  /// to ID 0 the caller notes it once per hand). True if it was a violation.
  bool note(std::uint8_t hand_id, Duration at, const protocol::Message& frame);

  /// Violations over all hands so far.
  [[nodiscard]] std::uint64_t violations() const { return violations_; }

 private:
  Duration minimum_;
  std::array<std::optional<Duration>, 256> last_{};
  std::uint64_t violations_ = 0;
};

}  // namespace dh3::sim
