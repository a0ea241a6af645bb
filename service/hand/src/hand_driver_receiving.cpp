// HandDriver: the frames a hand sends (replies, the unsolicited "initialization
// finished" frame) and what they change: the state, the active command's next
// step, the motions and the events.

#include <fmt/format.h>

#include "hand_driver.hpp"
#include "status_reading.hpp"

namespace dh3::hand {
namespace {

namespace reg = protocol::reg;
using protocol::Message;
using protocol::Register;

CommandResult ok(std::int32_t value, GraspOutcome grasp = GraspOutcome::none) {
  return CommandSuccess{value, grasp};
}

/// What the ending event of a stop's hold says; empty for other motions.
template <class Motion>
std::string hold_message(const Motion& motion) {
  return motion.stopped_target
             ? fmt::format("stopped by STOP on the way to {}", *motion.stopped_target)
             : std::string{};
}

}  // namespace

bool HandDriver::on_frame(const Message& message, TimePoint now) {
  if (const auto sent = slot_.take_answered(message)) {
    counters_.observe_round_trip(now - sent->sent);
    context_.latency.frame_to_reply.observe(now - sent->sent);
    on_answer(now);
    on_reply(*sent, message, now);
    flush(now);
    return true;
  }
  if (Initializing* init = initializing();
      init && message.reg == reg::kInitialize && online()->init_feedback_enabled) {
    // The unsolicited "initialization finished" frame (reading 3): confirm it.
    on_answer(now);
    init->check_now = true;
    flush(now);
    return true;
  }
  return false;
}

void HandDriver::on_discovered(const Message& reply, TimePoint now) {
  on_answer(now);
  apply_read(reply.reg, reply, now);
  flush(now);
}

void HandDriver::on_reply(const InFlight& sent, const Message& reply, TimePoint now) {
  switch (sent.purpose) {
    case Purpose::job:
      on_job_reply(sent.message, reply, now);
      return;
    case Purpose::probe:
    case Purpose::refresh:
    case Purpose::poll:
    case Purpose::init_check:
      apply_read(reply.reg, reply, now);
      return;
    case Purpose::confirm_position:
      apply_read(reply.reg, reply, now);
      if (fingers_.rechecking())
        on_grip_status(static_cast<std::int32_t>(FingerStatus::arrived), now);
      fingers_.read_answered();
      on_position_confirmed();
      return;
    case Purpose::confirm_rotation:
      apply_read(reply.reg, reply, now);
      if (rotation_.rechecking()) {
        on_rotation_status(static_cast<std::int32_t>(RotationStatus::arrived), now);
      }
      rotation_.read_answered();
      return;
  }
}

void HandDriver::on_position_confirmed() {
  if (const MotionWaiter* waiter = ledger_.motion_waiter(); waiter && waiter->outcome) {
    ledger_.finish_motion_waiter(ok(state_.position, *waiter->outcome));
  }
}

void HandDriver::apply_read(Register r, const Message& reply, TimePoint now) {
  if (r == reg::kPosition) {
    state_.position = reply.data;
    fingers_.value_read();
  } else if (r == reg::kGripStatus) {
    on_grip_status(protocol::status_value(reply), now);
  } else if (r == reg::kRotation) {
    state_.rotation = reply.data;
    rotation_.value_read();
  } else if (r == reg::kRotationStatus) {
    on_rotation_status(protocol::status_value(reply), now);
  } else if (r == reg::kClosingForce) {
    state_.closing_force = reply.data;
  } else if (r == reg::kOpeningForce) {
    state_.opening_force = reply.data;
  } else if (r == reg::kFirmwareVersion) {
    state_.firmware_version = reply.data;
  } else if (r == reg::kInitialize) {
    on_initialized_flag(reply.data, now);
  } else if (r == reg::kInitFeedback) {
    if (Online* on = online())
      on->init_feedback_enabled = reply.data == protocol::kInitFeedbackEnabled;
  }
}

// ---------------------------------------------------------------------------
// Commands

void HandDriver::on_job_reply(const Message& sent, const Message& reply, TimePoint now) {
  if (sent.access == protocol::Access::write) {
    if (!on_write_echo(sent, reply, now)) return;
  } else {
    apply_read(sent.reg, reply, now);
  }
  if (active()) advance_job(reply, now);  // else: cancelled while its frame was in flight
}

bool HandDriver::on_write_echo(const Message& sent, const Message& reply, TimePoint now) {
  // The hand echoes what it applied; 0x0801 answers its new value, 0xA5.
  if (sent.reg != reg::kInitFeedback && reply.data != sent.data) {
    const std::string why = fmt::format("hand answered {} to a write of {} = {}", reply.data,
                                        protocol::name(sent.reg), sent.data);
    emit(EventKind::fault, now, reply.data, why);
    if (active()) {
      set_error(CommandError::failed, why);
      ledger_.finish_active(fail(CommandError::failed));
    }
    return false;
  }
  if (sent.reg == reg::kClosingForce) state_.closing_force = reply.data;
  if (sent.reg == reg::kOpeningForce) state_.opening_force = reply.data;
  if (sent.reg == reg::kInitFeedback) {
    if (Online* on = online()) on->init_feedback_enabled = true;
  }
  if (sent.reg == reg::kInitialize) {
    // Initialization (re)started: not initialized until 0x0802 reads 1.
    set_init(Initializing{now + options_.init_timeout, now + options_.poll_interval_moving});
    fingers_.forget_motion();
    rotation_.forget_motion();
  }
  return true;
}

void HandDriver::advance_job(const Message& reply, TimePoint now) {
  ActiveJob& job = *active();
  const Command& command = job.job.command;
  if (job.check_initialized_first) {
    job.check_initialized_first = false;
    if (state_.initialized) return;  // on to the command's own frames
    if (command.kind == CommandKind::stop) {
      ledger_.finish_active(ok(state_.position));  // nothing moves before initialization
    } else {
      set_error(CommandError::not_initialized,
                fmt::format("{} before initialization", to_string(command.kind)));
      ledger_.finish_active(fail(CommandError::not_initialized));
    }
    return;
  }
  if (auto* step = std::get_if<InitializeStep>(&job.step); step) {
    if (*step == InitializeStep::enable_feedback) {
      *step = InitializeStep::start;
      return;
    }
    // Echoed: never re-sent from here on; wait for the hand to finish.
    const TimePoint deadline = now + command.timeout.value_or(options_.init_timeout);
    if (Initializing* init = initializing()) init->deadline = deadline;
    ledger_.active_waits_for_init(deadline);
    return;
  }
  if (auto* step = std::get_if<GraspStep>(&job.step); step && *step == GraspStep::set_force) {
    *step = GraspStep::close;
    return;
  }
  if (auto* step = std::get_if<StopStep>(&job.step); step) {
    advance_stop(*step, reply);
    return;
  }
  if (command.kind == CommandKind::grasp || command.kind == CommandKind::release) {
    const TimePoint deadline = now + command.timeout.value_or(options_.motion_timeout);
    ledger_.active_waits_for_motion(deadline, finger_epoch_);
    return;
  }
  if (command.kind == CommandKind::read_register &&
      (command.reg == reg::kGripStatus || command.reg == reg::kRotationStatus)) {
    ledger_.finish_active(ok(protocol::status_value(reply)));
    return;
  }
  ledger_.finish_active(ok(reply.data));
}

void HandDriver::advance_stop(StopStep& step, const Message& reply) {
  switch (step) {
    case StopStep::read_position:
      // An axis at rest is already held: writing its position would make a
      // motion, and an arrival event, of nothing.
      active()->held = reply.data;
      state_.position = reply.data;
      step = fingers_.motion() ? StopStep::hold_position : StopStep::read_rotation;
      return;
    case StopStep::hold_position:
      step = StopStep::read_rotation;
      return;
    case StopStep::read_rotation:
      active()->held = reply.data;
      state_.rotation = reply.data;
      if (rotation_.motion()) {
        step = StopStep::hold_rotation;
      } else {
        ledger_.finish_active(ok(state_.position));
      }
      return;
    case StopStep::hold_rotation:
      ledger_.finish_active(ok(state_.position));
      return;
  }
}

// ---------------------------------------------------------------------------
// Initialization and status

void HandDriver::on_initialized_flag(std::int32_t value, TimePoint now) {
  if (initializing()) {
    if (value != 1) return;
    set_init(Initialized{});
    emit(EventKind::initialized, now, value);
    ledger_.finish_init_waiter(ok(value));
    return;
  }
  if (value == 1) {
    set_init(Initialized{});
    return;
  }
  const bool was_initialized = state_.initialized;
  set_init(NotInitialized{});
  if (was_initialized && online()) {
    emit(EventKind::fault, now, value,
         "the hand reports it is not initialized any more (was it power-cycled?)");
  }
}

void HandDriver::on_grip_status(std::int32_t status, TimePoint now) {
  const GripReading reading =
      read_grip_status(status, FingerView{state_.grip, fingers_.motion(), hold_untouched_,
                                          state_.position, fingers_.last_undefined()});
  if (!fingers_.take_status(status == static_cast<std::int32_t>(FingerStatus::moving),
                            reading.stale,
                            status == static_cast<std::int32_t>(FingerStatus::arrived))) {
    return;
  }
  if (reading.hold_starts) hold_untouched_ = true;
  if (reading.motion_ended) {
    finger_motion_ended(*reading.grip, *reading.event, now);
    return;
  }
  if (reading.grip) state_.grip = *reading.grip;
  if (reading.event == EventKind::dropped) {
    emit(EventKind::dropped, now, status,
         fmt::format("object lost at position {} while holding", state_.position));
  } else if (reading.event == EventKind::fault) {
    fingers_.undefined_reported(status);
    emit(EventKind::fault, now, status,
         fmt::format("grip status {} is not one the document defines", status));
  }
}

void HandDriver::finger_motion_ended(GripState grip, EventKind event, TimePoint now) {
  state_.grip = grip;
  // The event goes out on this read, one interval at most from the change.
  // Where the fingers stopped is read next: a status sample then says it, and
  // a grasp or release waiting for the motion ends with it. The event carries
  // it when it is known already: the read that rechecked this arrival, or a
  // read during the motion that found them at the target, with a status that
  // says they stopped without a catch.
  const bool stopped_at_target =
      event != EventKind::grasped && fingers_.read_at_target(state_.position);
  const bool known = stopped_at_target || fingers_.rechecking();
  const FingerMotion motion = *fingers_.motion();
  fingers_.end(stopped_at_target);
  // A grasp is explained by the force it holds with; an arrival by its status.
  emit_event(event, now, event == EventKind::grasped ? state_.closing_force : 2,
             hold_message(motion), known ? std::optional(state_.position) : std::nullopt,
             motion.reported_target());
  if (MotionWaiter* waiter = ledger_.motion_waiter();
      waiter && waiter->epoch == finger_epoch_ && !waiter->outcome) {
    // The result carries where the fingers stopped, after the same read.
    waiter->outcome = grip == GripState::grasped  ? GraspOutcome::grasped
                      : grip == GripState::missed ? GraspOutcome::missed
                                                  : GraspOutcome::none;
  }
  if (stopped_at_target) on_position_confirmed();
}

void HandDriver::on_rotation_status(std::int32_t status, TimePoint now) {
  const RotationReading reading = read_rotation_status(
      status, RotationView{rotation_.motion(), state_.rotation, rotation_.last_undefined()});
  if (!rotation_.take_status(status == static_cast<std::int32_t>(RotationStatus::moving),
                             reading.stale,
                             status == static_cast<std::int32_t>(RotationStatus::arrived))) {
    return;
  }
  if (reading.state) state_.rotation_state = *reading.state;
  if (reading.motion_ended) {
    // Reported now; where it stopped is read next unless a read during the
    // rotation found it at its target (or the read rechecking it is this one).
    const bool at_target =
        *reading.event == EventKind::rotation_arrived && rotation_.read_at_target(state_.rotation);
    const bool known = at_target || rotation_.rechecking();
    const RotationMotion motion = *rotation_.motion();
    rotation_.end(at_target);
    std::string message =
        *reading.event == EventKind::rotation_blocked
            ? fmt::format("rotation blocked on the way to {}", motion.reported_target())
            : hold_message(motion);
    emit_event(*reading.event, now, status, std::move(message),
               known ? std::optional(state_.rotation) : std::nullopt, motion.reported_target());
  } else if (reading.event == EventKind::fault) {
    rotation_.undefined_reported(status);
    emit(EventKind::fault, now, status,
         fmt::format("rotation status {} is not one the document defines", status));
  }
}

}  // namespace dh3::hand
