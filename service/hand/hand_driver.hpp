#pragma once
// One DH-3 hand as the bus loop drives it: its state machine (configured ->
// online -> initializing -> ready, offline after consecutive timeouts), its
// command queue, the one frame it has in flight, its status poller and the
// detection of the events a user cares about. Loop thread only; the scheduler
// decides when the hand may send and hands it the replies addressed to it.
//
// How it reads what the hand says (docs/protocol-notes.md readings 1-3, 9):
// - A reply matches the frame in flight on (hand, function, sub-function); any
//   other frame is unexpected, except an 0x0802 frame while initializing, which
//   is the unsolicited "initialization finished" signal and is confirmed by
//   reading 0x0802.
// - Grip status 3 is "caught" (event grasped). Status 2 after a finger motion
//   is "arrived", unless the motion was a grasp or a move to 0 (fully closed):
//   then nothing was there to catch (event missed). Status leaving 3 while no
//   finger command was sent since the catch is a drop. A status 2 or 3 that
//   cannot belong to the running motion (position far from the new target, or
//   3 while opening) is a stale reading from before the command and ignored.
// - Before any motion command, the hand's initialization flag (0x0802) is read
//   if it is not known yet, so a command right after start-up is not refused
//   for lack of knowledge.

#include <atomic>
#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bus/bus.hpp"
#include "hand/bus_scheduler.hpp"
#include "hand/hand_counters.hpp"
#include "hand/hand_types.hpp"
#include "protocol/codec.hpp"

namespace dh3::hand {

/// What a driver needs from its scheduler. Shared by every hand of a bus.
struct DriverContext {
  const SchedulerOptions& options;
  HandObserver& observer;
  std::string bus_name;
  /// Called with every published state (for the scheduler's snapshot).
  std::function<void(const HandState&)> on_published;
  std::atomic<std::uint64_t>& retries;
  std::atomic<std::uint64_t>& timeouts;
  std::atomic<std::uint64_t>& unexpected_frames;
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

  struct Job {
    Command command;
    Completion done;
    TimePoint submitted{};
  };

  /// Adds a command (already validated and counted in `queued`).
  void enqueue(Job job, TimePoint now);

  /// The frame to send now, if this hand has one and its pacing allows; it is
  /// then in flight until a reply matches it or it times out.
  [[nodiscard]] std::optional<protocol::Message> next_frame(TimePoint now);
  /// The frame returned by next_frame() could not be sent (would_block): it
  /// is offered again on the next call.
  void unsend();

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
  /// A discovery probe (firmware-version read) sent by the scheduler was
  /// answered by this new hand: it is online, its state is read afresh.
  void on_discovered(const protocol::Message& reply, TimePoint now);

 private:
  enum class Purpose : std::uint8_t { job, poll, probe, refresh, init_check, confirm_position };

  struct InFlight {
    protocol::Message message;
    Purpose purpose = Purpose::poll;
    TimePoint sent{};
    TimePoint deadline{};
    Duration reply_timeout{};
    int attempts = 1;
    bool retryable = true;
  };

  /// A command that finished sending and waits for the hand to get somewhere.
  struct Waiter {
    Job job;
    TimePoint deadline{};
    std::uint64_t epoch = 0;  ///< finger motion it waits for (grasp, release)
    bool confirming = false;  ///< outcome known, reading the final position
    GraspOutcome outcome = GraspOutcome::none;
  };

  struct ActiveJob {
    Job job;
    int stage = 0;
    std::int32_t held = -1;    ///< stop: the position / rotation read, to be written back
    bool motion_sent = false;  ///< its motion frame went out: it can no longer be taken back
  };

  // Sending.
  [[nodiscard]] std::optional<protocol::Message> job_frame(TimePoint now);
  [[nodiscard]] std::optional<protocol::Message> background_frame(TimePoint now);
  void start_next_job(TimePoint now);
  protocol::Message send(protocol::Message message, Purpose purpose, TimePoint now, bool retryable,
                         Duration reply_timeout);

  // Receiving.
  void on_reply(const InFlight& sent, const protocol::Message& reply, TimePoint now);
  void on_job_reply(const protocol::Message& sent, const protocol::Message& reply, TimePoint now);
  void apply_read(protocol::Register reg, const protocol::Message& reply, TimePoint now);
  void on_grip_status(std::int32_t status, TimePoint now);
  void on_rotation_status(std::int32_t status, TimePoint now);
  void on_initialized_flag(std::int32_t value, TimePoint now);
  void on_answer(TimePoint now);
  void on_timeout(TimePoint now);

  // Finishing.
  void finish_active(const CommandResult& result);
  void finish_waiter(std::optional<Waiter>& waiter, const CommandResult& result);
  void fail_everything(CommandError error);
  void cancel_motion(bool fingers, bool rotation);
  void go_offline(TimePoint now, const std::string& why);

  // Motion bookkeeping.
  void finger_motion_sent(std::int32_t target, bool gripping);
  void rotation_motion_sent(std::int32_t target);
  void finger_motion_ended(GripState state, EventKind event);
  void emit_ending_event(TimePoint now);

  void emit(EventKind kind, TimePoint now, std::int32_t value = 0, std::string message = {},
            std::optional<std::int32_t> position = {}, std::optional<std::int32_t> target = {});
  /// Counts the job's result and queues its completion for flush().
  void complete(Job& job, const CommandResult& result);
  void set_error(CommandError error, std::string message);
  /// Publishes the state if it changed, then the events, then the completions,
  /// so that whoever hears of an event or a result finds the state behind it.
  void flush(TimePoint now);
  [[nodiscard]] Duration reply_timeout_for(const Job& job) const;
  [[nodiscard]] bool moving() const;
  [[nodiscard]] std::string label() const;

  DriverContext& context_;
  const SchedulerOptions& options_;
  std::atomic<int>& queued_;
  HandCounters& counters_;
  bool anonymous_;
  HandState state_;
  HandState published_;
  bool ever_published_ = false;

  std::deque<Job> queue_;
  std::optional<ActiveJob> active_;
  std::optional<Waiter> init_waiter_;
  std::optional<Waiter> motion_waiter_;
  std::optional<InFlight> in_flight_;
  std::optional<InFlight> resend_;  ///< timed out (or not sent), to be sent again

  TimePoint next_send_at_{};
  int consecutive_timeouts_ = 0;
  TimePoint next_probe_at_{};

  // Status polling: a round reads these in turn; rounds start every
  // poll_interval_moving while something moves, poll_interval_idle otherwise.
  std::size_t poll_index_ = 0;
  std::size_t round_length_ = 0;
  bool poll_round_running_ = false;
  TimePoint next_poll_round_at_{};
  std::deque<protocol::Register> refresh_;  ///< read afresh after coming online

  // Initialization.
  bool init_known_ = false;    ///< 0x0802 read at least once since online
  bool initializing_ = false;  ///< an initialization runs; 0x0802 is watched
  TimePoint init_deadline_{};
  TimePoint next_init_check_at_{};
  bool init_check_now_ = false;  ///< the unsolicited frame came: confirm at once
  bool init_feedback_enabled_ = false;

  // Finger motion: epoch counts position writes sent.
  std::uint64_t finger_epoch_ = 0;
  bool finger_motion_active_ = false;
  bool finger_motion_gripping_ = false;
  bool finger_motion_closing_ = false;
  bool finger_command_since_caught_ = true;
  bool need_position_confirm_ = false;
  bool rotation_motion_active_ = false;
  struct PendingEvent {
    EventKind kind;
    std::int32_t value;
  };
  std::optional<PendingEvent> ending_event_;  ///< waits for the confirming position read
  std::int32_t last_odd_status_ = 0;  ///< a status value outside the document, reported once

  std::vector<HandEvent> pending_events_;
  std::vector<std::pair<Completion, CommandResult>> pending_completions_;
};

}  // namespace dh3::hand
