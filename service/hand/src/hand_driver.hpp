#pragma once
// One DH-3 hand as the bus loop drives it: its link (offline -> online, and back
// after consecutive timeouts, link loss or shutdown), its initialization, the
// steps of its commands, its status poller and the detection of the events a
// user cares about. The states are the types of
// hand_driver_states.hpp; what a status value means is status_reading.hpp.
// Loop thread only; the scheduler decides when the hand may send and hands it
// the replies addressed to it.
//
// How it reads what the hand says (docs/protocol-notes.md readings 1-3, 9):
// - A reply matches the frame in flight on (hand, function, sub-function); any
//   other frame is unexpected, except an 0x0802 frame while initializing with
//   the feedback (0x0801) enabled, which is the unsolicited "initialization
//   finished" signal and is confirmed by reading 0x0802.
// - Grip and rotation status values: see status_reading.hpp.
// - Before any motion command, the hand's initialization flag (0x0802) is read
//   if it is not known yet, so a command right after start-up is not refused
//   for lack of knowledge.
//
// It coordinates its collaborators, each owning its state: a FrameSlot (the
// one frame in flight, its re-send, the pacing; frame_slot.hpp), a
// CommandLedger (the commands queued, being sent or waiting for the hand, and
// their completions; command_ledger.hpp), a HandOutbox (what a pass
// reports, held until the pass ends; hand_outbox.hpp) and an AxisWatch per
// axis, fingers and rotation (the motion, the read of where it stopped, an
// arrival that may be stale; axis_watch.hpp). Its own code:
// hand_driver.cpp (commands in, frames out, lifecycle, time, reporting) and
// hand_driver_receiving.cpp (replies and what they change).

#include <atomic>
#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "axis_watch.hpp"
#include "command_ledger.hpp"
#include "dh3/bus/bus.hpp"
#include "dh3/hand/bus_scheduler.hpp"
#include "dh3/hand/hand_roster.hpp"
#include "dh3/hand/hand_types.hpp"
#include "dh3/protocol/codec.hpp"
#include "frame_slot.hpp"
#include "hand_counters.hpp"
#include "hand_driver_states.hpp"
#include "hand_outbox.hpp"

namespace dh3::hand {

/// What a driver needs from its scheduler. Shared by every hand of a bus.
struct DriverContext {
  const SchedulerOptions& options;
  HandObserver& observer;
  std::string bus_name;
  /// The bus's hands and their published states, which other threads read.
  HandRoster& roster;
  std::atomic<std::uint64_t>& unexpected_frames;
  BusLatencyCounters& latency;
  /// Makes the bus loop run a pass soon (from any thread): a group's release.
  std::function<void()> wake;
};

class HandDriver {
 public:
  /// `queued` counts this hand's commands that wait for their turn; submit()
  /// raises it on the caller's thread, the driver lowers it as they leave the
  /// queue. `anonymous`: ID 0, used only to read or set the CAN ID of whichever
  /// hand is there; it is never polled, probed or reported. `counters`: this
  /// hand's, owned by the scheduler.
  HandDriver(HandConfig config, DriverContext& context, std::atomic<int>& queued,
             HandCounters& counters, TimePoint now, bool anonymous = false);

  using Job = DriverJob;

  /// Adds a command (already validated and counted in `queued`).
  void enqueue(Job job, TimePoint now);

  /// The frame to send now, if this hand has one and its pacing allows; it is
  /// then in flight until a reply matches it or it times out.
  [[nodiscard]] std::optional<protocol::Message> next_frame(TimePoint now);
  /// A group member's held frame, once its group released it (and only
  /// then): the scheduler sends these first in a pass, back to back.
  [[nodiscard]] std::optional<protocol::Message> next_group_frame(TimePoint now);
  /// The frame returned by next_frame() could not be sent (would_block): it
  /// is offered again on the next call.
  void unsend() { slot_.unsend(); }
  /// The frame returned by next_frame() (next_group_frame()) left at `left`:
  /// its reply timeout counts from then.
  void frame_left(TimePoint left) { slot_.left_at(left); }
  /// Sends nothing before `until` (the scheduler's pacing across senders: a
  /// discovery probe it sent itself, a frame to ID 0 that this hand received).
  void hold_sends_until(TimePoint until) { slot_.hold_sends_until(until); }
  /// The earliest time this hand's pacing lets it send again.
  [[nodiscard]] TimePoint paced_until() const { return slot_.paced_until(); }
  /// It has a command frame (or a re-send) ready to go once its pacing allows.
  [[nodiscard]] bool has_command_frame() const;

  /// A frame from this hand's CAN ID. Returns false if it matched nothing.
  bool on_frame(const protocol::Message& message, TimePoint now);
  /// Timeouts, retries, deadlines of waiting commands, poll schedule.
  void on_time(TimePoint now);

  /// The bus went down: everything pending ends with BUS_DOWN, hand offline.
  void on_link_down(TimePoint now);
  /// The bus is back: probe the hand at once.
  void on_link_up(TimePoint now);
  /// Shutdown: everything pending ends with CANCELLED, hand offline.
  void shut_down(TimePoint now);

  /// When this hand next needs the loop (send due, deadline), if ever.
  [[nodiscard]] std::optional<TimePoint> next_wakeup() const;
  [[nodiscard]] const HandState& state() const { return state_; }
  [[nodiscard]] std::uint8_t can_id() const { return state_.can_id; }
  [[nodiscard]] bool anonymous() const { return anonymous_; }

  /// Publishes the current state (a configured hand, before it answered).
  void publish_now(TimePoint now);
  /// Starts from what a standby saw of this hand on the bus (ObservedHands):
  /// its initialization, forces, position, grip and rotation stand until the
  /// hand's own replies say otherwise. Before the loop runs.
  void warm(const HandState& seen);
  /// A discovery probe (firmware-version read) sent by the scheduler was
  /// answered by this new hand: it is online, its state is read afresh.
  void on_discovered(const protocol::Message& reply, TimePoint now);

 private:
  // Frames out (hand_driver.cpp).
  [[nodiscard]] std::optional<protocol::Message> job_frame(TimePoint now);
  [[nodiscard]] std::optional<protocol::Message> initialize_frame(TimePoint now,
                                                                  InitializeStep step);
  [[nodiscard]] std::optional<protocol::Message> grasp_frame(TimePoint now, GraspStep step);
  [[nodiscard]] std::optional<protocol::Message> stop_frame(TimePoint now, StopStep step);
  [[nodiscard]] std::optional<protocol::Message> background_frame(TimePoint now);
  [[nodiscard]] std::optional<protocol::Message> online_frame(Online& online, TimePoint now);
  void start_next_job(TimePoint now);
  /// Whether the active job's next frame is the one its group holds.
  [[nodiscard]] bool at_group_gate() const;
  /// The active job's frame is at its group's gate: true if it may go now.
  [[nodiscard]] bool pass_group_gate(TimePoint now);
  /// Ready and held for the group: nothing else goes to the hand meanwhile.
  [[nodiscard]] bool holding_for_group() const;
  protocol::Message send_job(protocol::Message message, TimePoint now);
  /// `stopped_target`: for a stop's hold, the target of the motion it ended
  /// (the hold's ending event reports it).
  void finger_motion_sent(std::int32_t target, bool gripping,
                          std::optional<std::int32_t> stopped_target = std::nullopt);
  void rotation_motion_sent(std::int32_t target,
                            std::optional<std::int32_t> stopped_target = std::nullopt);

  // Receiving (hand_driver_receiving.cpp).
  void on_reply(const InFlight& sent, const protocol::Message& reply, TimePoint now);
  void on_job_reply(const protocol::Message& sent, const protocol::Message& reply, TimePoint now);
  /// A write's echo; false if the hand refused it (the job then failed).
  bool on_write_echo(const protocol::Message& sent, const protocol::Message& reply, TimePoint now);
  /// The next step of the active job after its frame was answered.
  void advance_job(const protocol::Message& reply, TimePoint now);
  void advance_stop(StopStep& step, const protocol::Message& reply);
  void apply_read(protocol::Register reg, const protocol::Message& reply, TimePoint now);
  void on_grip_status(std::int32_t status, TimePoint now);
  void on_rotation_status(std::int32_t status, TimePoint now);
  void on_initialized_flag(std::int32_t value, TimePoint now);
  /// Where the fingers stopped was read: a grasp or release waiting for it ends.
  void on_position_confirmed();
  void finger_motion_ended(GripState grip, EventKind event, TimePoint now);

  // Lifecycle and time (hand_driver.cpp).
  void on_answer(TimePoint now);
  /// A frame went unanswered: re-sent (FrameSlot decides), or what it was for fails.
  void on_timeout(const FrameSlot::Expired& expired, TimePoint now);
  void on_init_deadlines(TimePoint now);
  /// The one reset path: going offline, link loss and shutdown.
  void lose_link(TimePoint now, LinkLoss loss, const std::string& why);
  void set_init(InitState init);
  [[nodiscard]] ActiveJob* active() { return ledger_.active(); }
  [[nodiscard]] const ActiveJob* active() const { return ledger_.active(); }
  [[nodiscard]] Online* online() { return std::get_if<Online>(&link_); }
  [[nodiscard]] const Online* online() const { return std::get_if<Online>(&link_); }
  [[nodiscard]] Initializing* initializing();
  [[nodiscard]] const Initializing* initializing() const;
  [[nodiscard]] bool init_known() const;
  /// What to poll how often, from what the hand is doing now.
  [[nodiscard]] PollPlan poll_plan() const;

  // Reporting (hand_driver.cpp).
  /// An event with the position as last read and the target in force.
  void emit(EventKind kind, TimePoint now, std::int32_t value = 0, std::string message = {});
  /// An event with the position and target given; for the end of a motion,
  /// `position` where the axis stopped if read after the end, `target` the one
  /// the event reports (reported_target()).
  void emit_event(EventKind kind, TimePoint now, std::int32_t value, std::string message,
                  std::optional<std::int32_t> position, std::int32_t target);
  void set_error(CommandError error, std::string message);
  /// Publishes the state if it changed, then the events, then the completions,
  /// so that whoever hears of an event or a result finds the state behind it.
  void flush(TimePoint now) { outbox_.deliver(state_, now); }
  [[nodiscard]] Duration reply_timeout_for(const Job& job) const;
  [[nodiscard]] std::string label() const;

  DriverContext& context_;
  const SchedulerOptions& options_;
  HandCounters& counters_;
  bool anonymous_;
  /// The hand's state, owned here on the loop thread; what other threads see is
  /// the copy it publishes to the roster (DriverContext::roster). `online` and
  /// `initialized` mirror link_ (initialized: as last known while unknown).
  HandState state_;
  /// Events and completions of this pass, delivered with the state at flush().
  HandOutbox outbox_;

  Link link_;
  int consecutive_timeouts_ = 0;

  // Commands: queued, being sent, waiting for the hand; their completions.
  CommandLedger ledger_;

  // Frames: the one in flight, its re-send, the pacing.
  FrameSlot slot_;
  /// Inside next_group_frame(): a released group frame may pass its gate.
  bool releasing_group_ = false;

  // Motions, one watch per axis. The epoch counts finger position writes sent.
  AxisWatch<FingerMotion> fingers_;
  AxisWatch<RotationMotion> rotation_;
  std::uint64_t finger_epoch_ = 0;
  bool hold_untouched_ = false;  ///< holding a catch, no finger command sent since
};

}  // namespace dh3::hand
