#include "hand/hand_driver.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdlib>

#include "hand/command_validation.hpp"

namespace dh3::hand {
namespace {

namespace reg = protocol::reg;
using protocol::Message;
using protocol::Register;

/// A status 2 only counts as arrival at the new target when the position read
/// is this close to it (percent); otherwise it is a stale reading.
constexpr std::int32_t kArrivalTolerance = 3;

/// Read in every status round; an idle round also reads 0x0802, so a hand that
/// rebooted (and lost its initialization) is noticed.
constexpr Register kPollRound[] = {reg::kPosition, reg::kGripStatus, reg::kRotation,
                                   reg::kRotationStatus, reg::kInitialize};
constexpr std::size_t kMovingRoundLength = 4;

/// Read afresh whenever a hand comes online.
constexpr Register kRefresh[] = {reg::kInitialize,    reg::kClosingForce, reg::kOpeningForce,
                                 reg::kPosition,      reg::kGripStatus,   reg::kRotation,
                                 reg::kRotationStatus};

bool moves_fingers(const Command& command) {
  switch (command.kind) {
    case CommandKind::move_to:
    case CommandKind::grasp:
    case CommandKind::release:
      return true;
    case CommandKind::write_register:
      return command.reg == reg::kPosition;
    default:
      return false;
  }
}

bool moves_rotation(const Command& command) {
  return command.kind == CommandKind::rotate_to ||
         (command.kind == CommandKind::write_register && command.reg == reg::kRotation);
}

bool needs_initialization(const Command& command) {
  return moves_fingers(command) || moves_rotation(command) || command.kind == CommandKind::stop;
}

bool same_published_fields(const HandState& a, const HandState& b) {
  return a.can_id == b.can_id && a.name == b.name && a.online == b.online &&
         a.initialized == b.initialized && a.grip == b.grip && a.position == b.position &&
         a.target_position == b.target_position && a.closing_force == b.closing_force &&
         a.opening_force == b.opening_force && a.rotation == b.rotation &&
         a.rotation_target == b.rotation_target && a.rotation_state == b.rotation_state &&
         a.firmware_version == b.firmware_version && a.last_error == b.last_error &&
         a.last_error_message == b.last_error_message;
}

CommandResult ok(std::int32_t value, GraspOutcome grasp = GraspOutcome::none) {
  return CommandSuccess{value, grasp};
}

}  // namespace

HandDriver::HandDriver(HandConfig config, DriverContext& context, std::atomic<int>& queued,
                       HandCounters& counters, TimePoint now, bool anonymous)
    : context_(context),
      options_(context.options),
      queued_(queued),
      counters_(counters),
      anonymous_(anonymous) {
  state_.can_id = config.can_id;
  state_.name = std::move(config.name);
  state_.updated_at = now;
  next_send_at_ = now;
  next_probe_at_ = now;
  next_poll_round_at_ = now;
}

std::string HandDriver::label() const {
  return state_.name.empty()
             ? fmt::format("{}/{}", context_.bus_name, state_.can_id)
             : fmt::format("{}/{} ({})", context_.bus_name, state_.can_id, state_.name);
}

// ---------------------------------------------------------------------------
// Commands in

void HandDriver::enqueue(Job job, TimePoint now) {
  const Command& command = job.command;
  if (command.kind == CommandKind::stop) {
    // Stop goes first and ends every motion not yet under way.
    cancel_motion(true, true);
    queue_.push_front(std::move(job));
  } else {
    // A newer motion supersedes the queued ones of the same axis (the hand
    // itself would do the same: "position command can be interrupted").
    cancel_motion(moves_fingers(command), moves_rotation(command));
    queue_.push_back(std::move(job));
  }
  flush(now);
}

void HandDriver::cancel_motion(bool fingers, bool rotation) {
  if (!fingers && !rotation) return;
  for (auto it = queue_.begin(); it != queue_.end();) {
    const bool superseded =
        (fingers && moves_fingers(it->command)) || (rotation && moves_rotation(it->command));
    if (superseded) {
      complete(*it, fail(CommandError::cancelled));
      queued_.fetch_sub(1);
      it = queue_.erase(it);
    } else {
      ++it;
    }
  }
  if (active_ && !active_->motion_sent &&
      ((fingers && moves_fingers(active_->job.command)) ||
       (rotation && moves_rotation(active_->job.command)))) {
    // Its frame in flight, if any, still gets its reply; the job is over.
    finish_active(fail(CommandError::cancelled));
  }
  if (fingers) finish_waiter(motion_waiter_, fail(CommandError::cancelled));
}

// ---------------------------------------------------------------------------
// Sending

Duration HandDriver::reply_timeout_for(const Job& job) const {
  const Command& command = job.command;
  if (command.kind == CommandKind::write_register && is_admin_register(command.reg)) {
    return options_.admin_reply_timeout;
  }
  return options_.reply_timeout;
}

Message HandDriver::send(Message message, Purpose purpose, TimePoint now, bool retryable,
                         Duration reply_timeout) {
  in_flight_ = InFlight{message, purpose, now, now + reply_timeout, reply_timeout, 1, retryable};
  next_send_at_ = now + options_.command_interval;
  return message;
}

std::optional<Message> HandDriver::next_frame(TimePoint now) {
  if (in_flight_ || now < next_send_at_) return std::nullopt;
  if (resend_) {
    InFlight again = *resend_;
    resend_.reset();
    again.sent = now;
    again.deadline = now + again.reply_timeout;
    in_flight_ = again;
    next_send_at_ = now + options_.command_interval;
    return again.message;
  }
  if (auto frame = job_frame(now)) {
    flush(now);
    return frame;
  }
  auto frame = anonymous_ ? std::nullopt : background_frame(now);
  flush(now);
  return frame;
}

void HandDriver::unsend() {
  if (!in_flight_) return;
  resend_ = *in_flight_;
  next_send_at_ = in_flight_->sent;
  in_flight_.reset();
}

void HandDriver::start_next_job(TimePoint now) {
  while (!active_ && !queue_.empty()) {
    Job job = std::move(queue_.front());
    queue_.pop_front();
    queued_.fetch_sub(1);
    if (job.command.timeout && now >= job.submitted + *job.command.timeout) {
      complete(job, fail(CommandError::timeout));
      continue;
    }
    ActiveJob next{std::move(job), 0, -1};
    if (needs_initialization(next.job.command)) {
      if (!init_known_) {
        next.stage = -1;  // read 0x0802 first
      } else if (!state_.initialized) {
        if (next.job.command.kind == CommandKind::stop) {
          // Nothing moves before initialization: there is nothing to stop.
          complete(next.job, ok(state_.position));
        } else {
          set_error(CommandError::not_initialized,
                    fmt::format("{} before initialization", to_string(next.job.command.kind)));
          complete(next.job, fail(CommandError::not_initialized));
        }
        continue;
      }
    }
    active_ = std::move(next);
  }
}

std::optional<Message> HandDriver::job_frame(TimePoint now) {
  start_next_job(now);
  if (!active_) return std::nullopt;
  const std::uint8_t id = state_.can_id;
  const Command& command = active_->job.command;
  const Duration timeout = reply_timeout_for(active_->job);
  auto read = [&](Register r) {
    return send(protocol::make_read(id, r), Purpose::job, now, true, timeout);
  };
  auto write = [&](Register r, std::int32_t value, bool retryable = true) {
    return send(protocol::make_write(id, r, value), Purpose::job, now, retryable, timeout);
  };
  if (active_->stage == -1) return read(reg::kInitialize);

  switch (command.kind) {
    case CommandKind::initialize:
      // The document's frames: enable the feedback, then initialize (data 0).
      return active_->stage == 0 ? write(reg::kInitFeedback, 0) : write(reg::kInitialize, 0);
    case CommandKind::move_to:
      finger_motion_sent(command.value, command.value == 0);
      return write(reg::kPosition, command.value);
    case CommandKind::release:
      finger_motion_sent(command.value, false);
      return write(reg::kPosition, command.value);
    case CommandKind::rotate_to:
      rotation_motion_sent(command.value);
      return write(reg::kRotation, command.value);
    case CommandKind::set_closing_force:
      return write(reg::kClosingForce, command.value);
    case CommandKind::set_opening_force:
      return write(reg::kOpeningForce, command.value);
    case CommandKind::read_register:
      return read(command.reg);
    case CommandKind::write_register:
      if (command.reg == reg::kPosition) finger_motion_sent(command.value, command.value == 0);
      if (command.reg == reg::kRotation) rotation_motion_sent(command.value);
      // CAN ID and baud rate reply only once stored: a re-send would store twice.
      return write(command.reg, command.value, !is_admin_register(command.reg));
    case CommandKind::grasp:
      if (active_->stage == 0) return write(reg::kClosingForce, command.value);
      finger_motion_sent(0, true);
      return write(reg::kPosition, 0);
    case CommandKind::stop:
      switch (active_->stage) {
        case 0:
          return read(reg::kPosition);
        case 1:
          finger_motion_sent(active_->held, false);
          return write(reg::kPosition, active_->held);
        case 2:
          return read(reg::kRotation);
        default:
          rotation_motion_sent(active_->held);
          return write(reg::kRotation, active_->held);
      }
  }
  return std::nullopt;
}

std::optional<Message> HandDriver::background_frame(TimePoint now) {
  const std::uint8_t id = state_.can_id;
  if (!state_.online) {
    if (now < next_probe_at_) return std::nullopt;
    next_probe_at_ = now + options_.offline_probe_interval;
    return send(protocol::make_read(id, reg::kFirmwareVersion), Purpose::probe, now, false,
                options_.reply_timeout);
  }
  if (need_position_confirm_) {
    need_position_confirm_ = false;
    return send(protocol::make_read(id, reg::kPosition), Purpose::confirm_position, now, true,
                options_.reply_timeout);
  }
  if (initializing_ && (init_check_now_ || now >= next_init_check_at_)) {
    init_check_now_ = false;
    next_init_check_at_ = now + options_.poll_interval_moving;
    return send(protocol::make_read(id, reg::kInitialize), Purpose::init_check, now, false,
                options_.reply_timeout);
  }
  if (!refresh_.empty()) {
    const Register r = refresh_.front();
    refresh_.pop_front();
    return send(protocol::make_read(id, r), Purpose::refresh, now, true, options_.reply_timeout);
  }
  if (!poll_round_running_) {
    if (now < next_poll_round_at_) return std::nullopt;
    poll_round_running_ = true;
    poll_index_ = 0;
    const bool idle = !moving() && !initializing_;
    next_poll_round_at_ =
        now + (idle ? options_.poll_interval_idle : options_.poll_interval_moving);
    round_length_ = idle ? std::size(kPollRound) : kMovingRoundLength;
  }
  const Register r = kPollRound[poll_index_++];
  if (poll_index_ >= round_length_) poll_round_running_ = false;
  return send(protocol::make_read(id, r), Purpose::poll, now, false, options_.reply_timeout);
}

bool HandDriver::moving() const {
  // Status 0 also means "default" (after power-on or initialization), so only
  // motions we commanded, or a drop in progress, count as moving.
  return finger_motion_active_ || rotation_motion_active_ || motion_waiter_.has_value();
}

void HandDriver::finger_motion_sent(std::int32_t target, bool gripping) {
  if (active_) active_->motion_sent = true;
  // A grasp or release waiting for the previous motion to end is superseded.
  finish_waiter(motion_waiter_, fail(CommandError::cancelled));
  ++finger_epoch_;
  finger_motion_active_ = true;
  finger_motion_gripping_ = gripping;
  finger_motion_closing_ = state_.position < 0 || target < state_.position;
  finger_command_since_caught_ = true;
  state_.target_position = target;
  state_.grip = GripState::moving;
  // A motion started while idle: poll soon, not at the idle period.
  next_poll_round_at_ = std::min(next_poll_round_at_, next_send_at_);
}

void HandDriver::rotation_motion_sent(std::int32_t target) {
  if (active_) active_->motion_sent = true;
  rotation_motion_active_ = true;
  state_.rotation_target = target;
  state_.rotation_state = RotationState::moving;
  next_poll_round_at_ = std::min(next_poll_round_at_, next_send_at_);
}

// ---------------------------------------------------------------------------
// Receiving

bool HandDriver::on_frame(const Message& message, TimePoint now) {
  if (in_flight_ && in_flight_->message.reg == message.reg) {
    // Matched on (hand, function, sub-function); the read/write byte is not
    // compared (docs/protocol-notes.md reading 1).
    const InFlight sent = *in_flight_;
    in_flight_.reset();
    counters_.observe_round_trip(now - sent.sent);
    on_answer(now);
    on_reply(sent, message, now);
    flush(now);
    return true;
  }
  if (message.reg == reg::kInitialize && initializing_) {
    // The unsolicited "initialization finished" frame (reading 3): confirm it.
    on_answer(now);
    init_check_now_ = true;
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

void HandDriver::on_answer(TimePoint now) {
  consecutive_timeouts_ = 0;
  if (state_.online || anonymous_) return;
  state_.online = true;
  init_known_ = false;
  refresh_.assign(std::begin(kRefresh), std::end(kRefresh));
  poll_round_running_ = false;
  next_poll_round_at_ = now;
  emit(EventKind::online, now, state_.firmware_version);
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
      emit_ending_event(now);
      if (motion_waiter_ && motion_waiter_->confirming) {
        finish_waiter(motion_waiter_, ok(state_.position, motion_waiter_->outcome));
      }
      return;
  }
}

void HandDriver::apply_read(Register r, const Message& reply, TimePoint now) {
  if (r == reg::kPosition) {
    state_.position = reply.data;
  } else if (r == reg::kGripStatus) {
    on_grip_status(protocol::status_value(reply), now);
  } else if (r == reg::kRotation) {
    state_.rotation = reply.data;
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
    init_feedback_enabled_ = reply.data == protocol::kInitFeedbackEnabled;
  }
}

void HandDriver::on_job_reply(const Message& sent, const Message& reply, TimePoint now) {
  const bool is_write = sent.access == protocol::Access::write;
  if (is_write) {
    // The hand echoes what it applied; 0x0801 answers its new value, 0xA5.
    const bool refused = sent.reg != reg::kInitFeedback && reply.data != sent.data;
    if (refused) {
      const std::string why = fmt::format("hand answered {} to a write of {} = {}", reply.data,
                                          protocol::name(sent.reg), sent.data);
      emit(EventKind::fault, now, reply.data, why);
      if (active_) {
        set_error(CommandError::failed, why);
        finish_active(fail(CommandError::failed));
      }
      return;
    }
    if (sent.reg == reg::kClosingForce) state_.closing_force = reply.data;
    if (sent.reg == reg::kOpeningForce) state_.opening_force = reply.data;
    if (sent.reg == reg::kInitFeedback) init_feedback_enabled_ = true;
    if (sent.reg == reg::kInitialize) {
      // Initialization (re)started: not initialized until 0x0802 reads 1.
      initializing_ = true;
      init_known_ = true;
      state_.initialized = false;
      finger_motion_active_ = false;
      rotation_motion_active_ = false;
      init_deadline_ = now + options_.init_timeout;
      next_init_check_at_ = now + options_.poll_interval_moving;
    }
  } else {
    apply_read(sent.reg, reply, now);
  }
  if (!active_) return;  // cancelled while its frame was in flight

  ActiveJob& job = *active_;
  const Command& command = job.job.command;
  if (job.stage == -1) {
    if (!state_.initialized && command.kind != CommandKind::stop) {
      set_error(CommandError::not_initialized,
                fmt::format("{} before initialization", to_string(command.kind)));
      finish_active(fail(CommandError::not_initialized));
    } else if (!state_.initialized) {
      finish_active(ok(state_.position));
    } else {
      job.stage = 0;
    }
    return;
  }

  switch (command.kind) {
    case CommandKind::initialize:
      if (job.stage == 0) {
        job.stage = 1;
        return;
      }
      {
        // Echoed: never re-sent from here on; wait for the hand to finish.
        finish_waiter(init_waiter_, fail(CommandError::cancelled));
        const Duration wait = command.timeout.value_or(options_.init_timeout);
        init_deadline_ = now + wait;
        init_waiter_ = Waiter{std::move(job.job), now + wait, 0, false, GraspOutcome::none};
        active_.reset();
      }
      return;
    case CommandKind::grasp:
      if (job.stage == 0) {
        job.stage = 1;
        return;
      }
      [[fallthrough]];
    case CommandKind::release: {
      finish_waiter(motion_waiter_, fail(CommandError::cancelled));
      const Duration wait = command.timeout.value_or(options_.motion_timeout);
      motion_waiter_ =
          Waiter{std::move(job.job), now + wait, finger_epoch_, false, GraspOutcome::none};
      active_.reset();
      return;
    }
    case CommandKind::stop:
      if (job.stage == 0 || job.stage == 2) {
        job.held = reply.data;
        if (job.stage == 0) state_.position = reply.data;
        if (job.stage == 2) state_.rotation = reply.data;
        ++job.stage;
        return;
      }
      if (job.stage == 1) {
        ++job.stage;
        return;
      }
      finish_active(ok(state_.position));
      return;
    case CommandKind::read_register: {
      const bool status = command.reg == reg::kGripStatus || command.reg == reg::kRotationStatus;
      finish_active(ok(status ? protocol::status_value(reply) : reply.data));
      return;
    }
    default:
      finish_active(ok(reply.data));
      return;
  }
}

void HandDriver::on_initialized_flag(std::int32_t value, TimePoint now) {
  init_known_ = true;
  if (initializing_) {
    if (value != 1) return;
    initializing_ = false;
    state_.initialized = true;
    emit(EventKind::initialized, now, value);
    finish_waiter(init_waiter_, ok(value));
    return;
  }
  if (value == 1) {
    state_.initialized = true;
  } else if (state_.initialized) {
    state_.initialized = false;
    emit(EventKind::fault, now, value,
         "the hand reports it is not initialized any more (was it power-cycled?)");
  }
}

void HandDriver::on_grip_status(std::int32_t status, TimePoint now) {
  const bool held_untouched = !finger_command_since_caught_;
  switch (status) {
    case static_cast<std::int32_t>(protocol::GripStatus::caught):
      if (finger_motion_active_ && !finger_motion_closing_) return;  // stale: we are opening
      finger_command_since_caught_ = false;
      if (finger_motion_active_) {
        finger_motion_ended(GripState::caught, EventKind::grasped);
      } else {
        state_.grip = GripState::caught;
      }
      return;
    case static_cast<std::int32_t>(protocol::GripStatus::moving):
    case static_cast<std::int32_t>(protocol::GripStatus::arrived): {
      if (state_.grip == GripState::caught && held_untouched) {
        // The document's drop detection: status left 3 with no command sent.
        state_.grip = GripState::dropped;
        emit(EventKind::dropped, now, status,
             fmt::format("object lost at position {} while holding", state_.position));
        return;
      }
      if (state_.grip == GripState::dropped && held_untouched) return;  // stays dropped
      if (status == static_cast<std::int32_t>(protocol::GripStatus::moving)) {
        // Without a motion of ours, 0 is the hand's "default": nothing to report.
        if (finger_motion_active_) state_.grip = GripState::moving;
        return;
      }
      if (finger_motion_active_) {
        const bool near_target =
            state_.position < 0 || state_.target_position < 0 ||
            std::abs(state_.position - state_.target_position) <= kArrivalTolerance;
        if (!near_target) return;  // stale: from before the new target
        if (finger_motion_gripping_) {
          finger_motion_ended(GripState::no_object, EventKind::missed);
        } else {
          finger_motion_ended(GripState::arrived, EventKind::arrived);
        }
      } else if (state_.grip != GripState::no_object) {
        state_.grip = GripState::arrived;
      }
      return;
    }
    default:
      if (status != last_odd_status_) {
        last_odd_status_ = status;
        emit(EventKind::fault, now, status,
             fmt::format("grip status {} is not one the document defines", status));
      }
      return;
  }
}

void HandDriver::finger_motion_ended(GripState grip, EventKind event) {
  state_.grip = grip;
  finger_motion_active_ = false;
  // The position was read before the status that ended the motion, so it may
  // be a poll old: the event waits for a fresh read of where the fingers stopped.
  // A grasp is explained by the force it holds with; an arrival by its status.
  ending_event_ = PendingEvent{event, event == EventKind::grasped ? state_.closing_force : 2};
  need_position_confirm_ = true;
  if (motion_waiter_ && motion_waiter_->epoch == finger_epoch_ && !motion_waiter_->confirming) {
    motion_waiter_->confirming = true;
    motion_waiter_->outcome = grip == GripState::caught      ? GraspOutcome::grasped
                              : grip == GripState::no_object ? GraspOutcome::missed
                                                             : GraspOutcome::none;
    need_position_confirm_ = true;  // the result carries where the fingers stopped
  }
}

void HandDriver::emit_ending_event(TimePoint now) {
  if (!ending_event_) return;
  const PendingEvent event = *ending_event_;
  ending_event_.reset();
  emit(event.kind, now, event.value);
}

void HandDriver::on_rotation_status(std::int32_t status, TimePoint now) {
  switch (status) {
    case static_cast<std::int32_t>(protocol::GripStatus::moving):
      if (rotation_motion_active_) state_.rotation_state = RotationState::moving;
      return;
    case static_cast<std::int32_t>(protocol::GripStatus::arrived):
      if (rotation_motion_active_) {
        const bool near_target =
            state_.rotation < 0 || state_.rotation_target < 0 ||
            std::abs(state_.rotation - state_.rotation_target) <= kArrivalTolerance;
        if (!near_target) return;
        rotation_motion_active_ = false;
        emit(EventKind::rotation_arrived, now, status, {}, state_.rotation, state_.rotation_target);
      }
      state_.rotation_state = RotationState::arrived;
      return;
    case static_cast<std::int32_t>(protocol::GripStatus::caught):
      if (rotation_motion_active_) {
        rotation_motion_active_ = false;
        emit(EventKind::rotation_blocked, now, status,
             fmt::format("rotation blocked at {} on the way to {}", state_.rotation,
                         state_.rotation_target),
             state_.rotation, state_.rotation_target);
      }
      state_.rotation_state = RotationState::blocked;
      return;
    default:
      if (status != last_odd_status_) {
        last_odd_status_ = status;
        emit(EventKind::fault, now, status,
             fmt::format("rotation status {} is not one the document defines", status));
      }
      return;
  }
}

// ---------------------------------------------------------------------------
// Time

void HandDriver::on_time(TimePoint now) {
  if (in_flight_ && now >= in_flight_->deadline) on_timeout(now);

  if (initializing_ && now >= init_deadline_) {
    initializing_ = false;
    const std::string why = fmt::format(
        "initialization did not finish within {} ms",
        std::chrono::duration_cast<std::chrono::milliseconds>(options_.init_timeout).count());
    emit(EventKind::init_failed, now, 0, why);
    set_error(state_.online ? CommandError::failed : CommandError::timeout, why);
    finish_waiter(init_waiter_, fail(state_.online ? CommandError::failed : CommandError::timeout));
  }
  if (init_waiter_ && now >= init_waiter_->deadline) {
    set_error(CommandError::timeout, "initialization did not finish within the command's timeout");
    finish_waiter(init_waiter_, fail(CommandError::timeout));
  }
  if (motion_waiter_ && now >= motion_waiter_->deadline) {
    set_error(CommandError::timeout, fmt::format("{} did not end (caught or arrived) in time",
                                                 to_string(motion_waiter_->job.command.kind)));
    finish_waiter(motion_waiter_, fail(CommandError::timeout));
  }
  // Commands with their own timeout that are still waiting for their turn.
  for (auto it = queue_.begin(); it != queue_.end();) {
    if (it->command.timeout && now >= it->submitted + *it->command.timeout) {
      complete(*it, fail(CommandError::timeout));
      queued_.fetch_sub(1);
      it = queue_.erase(it);
    } else {
      ++it;
    }
  }
  flush(now);
}

void HandDriver::on_timeout(TimePoint now) {
  const InFlight lost = *in_flight_;
  in_flight_.reset();
  context_.timeouts.fetch_add(1);
  counters_.count_timeout();
  ++consecutive_timeouts_;

  if (lost.retryable && lost.attempts <= options_.max_retries) {
    InFlight again = lost;
    ++again.attempts;
    resend_ = again;
    context_.retries.fetch_add(1);
    counters_.count_retry();
  } else {
    switch (lost.purpose) {
      case Purpose::job:
        if (active_) {
          set_error(CommandError::timeout,
                    fmt::format("no answer to {} after {} tries", protocol::describe(lost.message),
                                lost.attempts));
          finish_active(fail(CommandError::timeout));
        }
        break;
      case Purpose::confirm_position:
        emit_ending_event(now);
        if (motion_waiter_ && motion_waiter_->confirming) {
          finish_waiter(motion_waiter_, ok(state_.position, motion_waiter_->outcome));
        }
        break;
      default:
        break;  // polls and probes are simply read again later
    }
  }
  if (state_.online && !anonymous_ && consecutive_timeouts_ >= options_.offline_after_timeouts) {
    go_offline(now, fmt::format("{} requests in a row went unanswered", consecutive_timeouts_));
  }
}

void HandDriver::go_offline(TimePoint now, const std::string& why) {
  state_.online = false;
  init_known_ = false;
  initializing_ = false;
  finger_motion_active_ = false;
  rotation_motion_active_ = false;
  need_position_confirm_ = false;
  emit_ending_event(now);
  refresh_.clear();
  resend_.reset();
  poll_round_running_ = false;
  next_probe_at_ = now + options_.offline_probe_interval;
  set_error(CommandError::timeout, why);
  emit(EventKind::offline, now, consecutive_timeouts_, why);
  fail_everything(CommandError::timeout);
}

void HandDriver::on_link_down(TimePoint now) {
  in_flight_.reset();
  resend_.reset();
  fail_everything(CommandError::bus_down);
  if (state_.online && !anonymous_) {
    state_.online = false;
    emit(EventKind::offline, now, 0, "bus down");
  }
  set_error(CommandError::bus_down, "bus down");
  init_known_ = false;
  initializing_ = false;
  finger_motion_active_ = false;
  rotation_motion_active_ = false;
  need_position_confirm_ = false;
  emit_ending_event(now);
  refresh_.clear();
  poll_round_running_ = false;
  flush(now);
}

void HandDriver::on_link_up(TimePoint now) {
  consecutive_timeouts_ = 0;
  next_probe_at_ = now;
  next_send_at_ = now;
  flush(now);
}

void HandDriver::shut_down(TimePoint now) {
  in_flight_.reset();
  resend_.reset();
  fail_everything(CommandError::cancelled);
  initializing_ = false;
  if (state_.online && !anonymous_) {
    state_.online = false;
    emit(EventKind::offline, now, 0, "service stopping");
  }
  flush(now);
}

void HandDriver::fail_everything(CommandError error) {
  if (active_) finish_active(fail(error));
  while (!queue_.empty()) {
    complete(queue_.front(), fail(error));
    queued_.fetch_sub(1);
    queue_.pop_front();
  }
  finish_waiter(init_waiter_, fail(error));
  finish_waiter(motion_waiter_, fail(error));
}

std::optional<TimePoint> HandDriver::next_wakeup() const {
  std::optional<TimePoint> earliest;
  auto consider = [&](TimePoint t) {
    if (!earliest || t < *earliest) earliest = t;
  };
  if (in_flight_) {
    consider(in_flight_->deadline);
  } else {
    const bool work_now = resend_ || active_ || !queue_.empty();
    if (work_now) consider(next_send_at_);
    if (!anonymous_) {
      if (!state_.online) {
        consider(std::max(next_send_at_, next_probe_at_));
      } else if (need_position_confirm_ || init_check_now_ || !refresh_.empty() ||
                 poll_round_running_) {
        consider(next_send_at_);
      } else {
        consider(std::max(next_send_at_, next_poll_round_at_));
        if (initializing_) consider(std::max(next_send_at_, next_init_check_at_));
      }
    }
  }
  if (initializing_) consider(init_deadline_);
  if (init_waiter_) consider(init_waiter_->deadline);
  if (motion_waiter_) consider(motion_waiter_->deadline);
  for (const Job& job : queue_) {
    if (job.command.timeout) consider(job.submitted + *job.command.timeout);
  }
  return earliest;
}

// ---------------------------------------------------------------------------
// Finishing and reporting

void HandDriver::finish_active(const CommandResult& result) {
  if (!active_) return;
  complete(active_->job, result);
  active_.reset();
}

void HandDriver::finish_waiter(std::optional<Waiter>& waiter, const CommandResult& result) {
  if (!waiter) return;
  complete(waiter->job, result);
  waiter.reset();
}

void HandDriver::complete(Job& job, const CommandResult& result) {
  counters_.count_command(job.command, result);
  if (job.done) pending_completions_.emplace_back(std::move(job.done), result);
}

void HandDriver::set_error(CommandError error, std::string message) {
  state_.last_error = error;
  state_.last_error_message = std::move(message);
}

void HandDriver::emit(EventKind kind, TimePoint now, std::int32_t value, std::string message,
                      std::optional<std::int32_t> position, std::optional<std::int32_t> target) {
  if (anonymous_) return;
  HandEvent event;
  event.kind = kind;
  event.can_id = state_.can_id;
  event.time = now;
  event.position = position.value_or(state_.position);
  event.target = target.value_or(state_.target_position);
  event.value = value;
  event.message = std::move(message);
  spdlog::info("{}: {}{}{}", label(), to_string(kind), event.message.empty() ? "" : ": ",
               event.message);
  pending_events_.push_back(std::move(event));
}

void HandDriver::publish_now(TimePoint now) {
  if (anonymous_) return;
  ever_published_ = false;
  flush(now);
}

void HandDriver::flush(TimePoint now) {
  if (!anonymous_ && (!ever_published_ || !same_published_fields(state_, published_))) {
    ever_published_ = true;
    ++state_.sequence;
    state_.updated_at = now;
    published_ = state_;
    if (context_.on_published) context_.on_published(state_);
    context_.observer.on_state(state_);
  }
  // Callbacks may call back into the scheduler (submit): take the lists first.
  auto events = std::move(pending_events_);
  pending_events_.clear();
  for (const HandEvent& event : events) context_.observer.on_event(event);
  auto completions = std::move(pending_completions_);
  pending_completions_.clear();
  for (auto& [done, result] : completions) done(result);
}

}  // namespace dh3::hand
