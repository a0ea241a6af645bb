#pragma once
// The states of one hand as HandDriver keeps them, one type per state, so that
// what a hand can be doing is read here rather than pieced together from flags.
//
//   Link            Offline (configured and not answered yet, or lost) --answer-->
//                   Online --timeouts / link down / shutdown--> Offline
//   Initialization  (only while Online) InitUnknown --0x0802 read--> NotInitialized or
//                   Initialized; the 0x0802 write echoed --> Initializing --flag 1-->
//                   Initialized; its deadline --> NotInitialized
//   Motions         FingerMotion and RotationMotion exist only while a commanded
//                   motion runs; its event goes out on the status read that ended it,
//                   and where the axis stopped is read next (the driver's AxisWatch)
//   Commands        ActiveJob: the one command being sent, with a step per frame for the
//                   commands that take several (initialize, grasp, stop); InitWaiter and
//                   MotionWaiter: commands whose frames are done and that wait for the
//                   hand to get somewhere
//   Frames          InFlight: the one frame sent and not answered yet, and why it was sent

#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <variant>

#include "dh3/base/clock.hpp"
#include "dh3/hand/bus_scheduler.hpp"
#include "dh3/hand/hand_types.hpp"
#include "dh3/hand/poll_policy.hpp"
#include "dh3/protocol/codec.hpp"

namespace dh3::hand {

/// A command as the driver receives it (validated, counted in its queue).
struct DriverJob {
  Command command;
  Completion done;
  TimePoint submitted{};
};

// ---- link ------------------------------------------------------------------

/// Initialization, known only while the hand answers.
struct InitUnknown {};  ///< 0x0802 not read since the hand came online
struct NotInitialized {};
struct Initializing {
  TimePoint deadline{};
  TimePoint next_check_at{};  ///< the next read of 0x0802
  bool check_now = false;     ///< the unsolicited "finished" frame came: confirm at once
};
struct Initialized {};
using InitState = std::variant<InitUnknown, NotInitialized, Initializing, Initialized>;

/// Status polling: what each status register was last read, so that the
/// plan of the moment (poll_policy.hpp) says which one is due.
struct PollSchedule {
  PollTimes last_read{};
  std::optional<std::size_t> previous;  ///< index of the register the last poll read
};

/// The hand does not answer (or has not yet): it is probed now and then.
struct Offline {
  TimePoint next_probe_at{};
};

/// The hand answers: its state is read afresh, then polled.
struct Online {
  InitState init = InitUnknown{};
  PollSchedule poll;
  std::deque<protocol::Register> refresh;  ///< read afresh after coming online
  /// 0x0801 enabled since the hand came online (its echo, or a read of 0xA5): only
  /// then is an unsolicited 0x0802 frame the "initialization finished" signal.
  bool init_feedback_enabled = false;
};

using Link = std::variant<Offline, Online>;

// ---- motions ---------------------------------------------------------------

/// A commanded finger motion, from its position write until its status ends it.
struct FingerMotion {
  std::int32_t target = 0;
  bool gripping = false;  ///< a grasp or a move to 0: ending without a catch is a miss
  bool closing = false;   ///< towards a smaller position: a catch can end it
  /// A grip status 0 was read since the motion began: the hand took the
  /// command, so a 2 read after it is this motion's arrival, not a reading
  /// from before it, wherever the position was last read.
  bool moving_seen = false;
  /// A stop's hold: the target of the motion the stop ended, which the
  /// ending event reports.
  std::optional<std::int32_t> stopped_target{};
  [[nodiscard]] std::int32_t reported_target() const { return stopped_target.value_or(target); }
};

/// A commanded rotation, from its write until its status ends it.
struct RotationMotion {
  std::int32_t target = 0;
  bool moving_seen = false;  ///< as FingerMotion's, for the rotation status
  std::optional<std::int32_t> stopped_target{};  ///< as FingerMotion's
  [[nodiscard]] std::int32_t reported_target() const { return stopped_target.value_or(target); }
};

// ---- commands --------------------------------------------------------------

/// The frames of the commands that take more than one, in order.
enum class InitializeStep : std::uint8_t { enable_feedback, start };
enum class GraspStep : std::uint8_t { set_force, close };
enum class StopStep : std::uint8_t { read_position, hold_position, read_rotation, hold_rotation };
struct SingleFrame {};
using JobStep = std::variant<SingleFrame, InitializeStep, GraspStep, StopStep>;

/// The step a command starts with.
[[nodiscard]] JobStep first_step(CommandKind kind);

/// The command being sent.
struct ActiveJob {
  DriverJob job;
  JobStep step;
  /// Whether the hand is initialized is not known yet: read 0x0802 before the
  /// command's own frames (a motion right after start-up is not refused blindly).
  bool check_initialized_first = false;
  std::int32_t held = -1;    ///< stop: the position / rotation read, to be written back
  bool motion_sent = false;  ///< its motion frame went out: it can no longer be taken back
  bool frame_sent = false;   ///< its first frame went out (counted in command_to_frame)
  /// A group member: its held frame was reported ready to the group, and the
  /// group released it (group_release.hpp).
  bool group_ready = false;
  bool group_released = false;
};

/// An initialize command whose frames were echoed, waiting for the hand to finish.
struct InitWaiter {
  DriverJob job;
  TimePoint deadline{};
};

/// A grasp or release whose position write was echoed, waiting for the motion to end.
struct MotionWaiter {
  DriverJob job;
  TimePoint deadline{};
  std::uint64_t epoch = 0;  ///< the finger motion it waits for
  /// Set once the motion ended: the result, sent after the final position is read.
  std::optional<GraspOutcome> outcome;
};

// ---- frames ----------------------------------------------------------------

enum class Purpose : std::uint8_t {
  job,
  poll,
  probe,
  refresh,
  init_check,
  confirm_position,
  confirm_rotation
};

/// The frame sent and not answered yet.
struct InFlight {
  protocol::Message message;
  Purpose purpose = Purpose::poll;
  TimePoint sent{};
  TimePoint deadline{};
  Duration reply_timeout{};
  int attempts = 1;
  bool retryable = true;
};

/// Why a hand's link ended; one reset path serves all three.
enum class LinkLoss : std::uint8_t {
  unanswered,  ///< consecutive timeouts
  bus_down,    ///< the bus went down
  shutdown,    ///< the service stops
};

}  // namespace dh3::hand
