#pragma once
// Which status registers a hand's poller reads and how often, from what the
// hand is doing. A hand may get a frame every command_interval at most, and
// dh3 hears of a catch, a slip or an arrival only by reading a status, so the
// floor for hearing of one is one interval. Fingers that hold an object or
// move, and a rotation in progress, have their status read in every frame
// the hand gets and nothing else polled but, every `during_motion`, the
// position (rotation) of the axis under way (an event goes out on that read;
// the driver reads where the motion stopped afterwards); a hand at rest reads
// its round now and then. Pure: it is told the time and what was read when; the
// driver keeps those.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>

#include "dh3/base/clock.hpp"
#include "dh3/protocol/registers.hpp"

namespace dh3::hand {

/// The registers the poller reads. Their order breaks ties between registers
/// due at the same time, so a hand at rest reads them in this order.
inline constexpr std::array<protocol::Register, 5> kPolledRegisters = {
    protocol::reg::kPosition, protocol::reg::kGripStatus, protocol::reg::kRotation,
    protocol::reg::kRotationStatus, protocol::reg::kInitialize};
inline constexpr std::size_t kPolledCount = kPolledRegisters.size();

/// What the fingers are doing, as far as polling cares.
enum class FingerActivity : std::uint8_t {
  idle,     ///< at rest, holding nothing
  holding,  ///< at rest on a caught object: it may slip
  closing,  ///< moving towards a smaller position: it may catch or arrive
  opening,  ///< moving towards a larger position: it will arrive
};

struct PollActivity {
  FingerActivity fingers = FingerActivity::idle;
  bool rotating = false;
  /// Initializing: its flag is read by the initialization check, and the rest
  /// as while moving (the hand calibrates).
  bool initializing = false;
};

/// The periods a plan is made of (SchedulerOptions' poll_interval_*).
struct PollIntervals {
  /// The status register that shows the change a state waits for.
  Duration watch = std::chrono::milliseconds(20);
  /// The registers of a hand that initializes (it calibrates).
  Duration moving = std::chrono::milliseconds(50);
  /// Everything else, and all of a hand at rest.
  Duration idle = std::chrono::milliseconds(500);
  /// The position of fingers that move, the rotation while it rotates, so a
  /// status sample shows the motion under way; zero: not read until the motion
  /// ends. Each such read takes a frame the watched status would have had: an
  /// event that falls due in that frame waits one frame more.
  Duration during_motion = std::chrono::milliseconds(200);
};

/// Per register of kPolledRegisters (same index): how often it is read, or
/// nullopt when it is not polled in this state.
struct PollPlan {
  std::array<std::optional<Duration>, kPolledCount> period{};
  friend bool operator==(const PollPlan&, const PollPlan&) = default;
};

/// When each register of kPolledRegisters was last read by a poll (nullopt:
/// not since the hand came online, so due at once).
using PollTimes = std::array<std::optional<TimePoint>, kPolledCount>;

[[nodiscard]] PollPlan plan_polls(const PollActivity& activity, const PollIntervals& intervals);

/// The index (into kPolledRegisters) of the register to read now, or nullopt if
/// none is due. Earliest due first (ties: kPolledRegisters order), except that
/// after a read of a slower register the fastest ones go first if due, so a
/// watched status waits at most one extra frame for the slow reads of a round.
/// `previous`: the register the last poll read.
[[nodiscard]] std::optional<std::size_t> next_poll(const PollPlan& plan, const PollTimes& last_read,
                                                   std::optional<std::size_t> previous,
                                                   TimePoint now);

/// When the next register of the plan falls due (nullopt: the plan polls nothing).
[[nodiscard]] std::optional<TimePoint> next_poll_due(const PollPlan& plan,
                                                     const PollTimes& last_read);

}  // namespace dh3::hand
