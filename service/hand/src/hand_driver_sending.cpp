// HandDriver: which frame goes next (a command's step, a re-send, a probe, a
// confirming read, a poll), and the motions that sending starts.

#include <fmt/format.h>

#include <algorithm>
#include <utility>

#include "dh3/hand/command_validation.hpp"
#include "dh3/hand/group_release.hpp"
#include "hand_driver.hpp"

namespace dh3::hand {
namespace {

namespace reg = protocol::reg;
using protocol::Message;
using protocol::Register;

}  // namespace

std::optional<Message> HandDriver::next_frame(TimePoint now) {
  if (!slot_.clear_to_send(now)) return std::nullopt;
  if (auto again = slot_.send_again(now)) return again;
  if (auto frame = job_frame(now)) {
    flush(now);
    return frame;
  }
  if (holding_for_group()) {
    flush(now);
    return std::nullopt;
  }
  auto frame = anonymous_ ? std::nullopt : background_frame(now);
  flush(now);
  return frame;
}

std::optional<Message> HandDriver::next_group_frame(TimePoint now) {
  if (!holding_for_group() || slot_.has_resend() || !slot_.clear_to_send(now)) return std::nullopt;
  releasing_group_ = true;
  auto frame = job_frame(now);
  releasing_group_ = false;
  flush(now);
  return frame;
}

bool HandDriver::has_command_frame() const {
  return !slot_.in_flight() && (slot_.has_resend() || ledger_.has_commands());
}

// ---------------------------------------------------------------------------
// Commands

void HandDriver::start_next_job(TimePoint now) {
  while (!active()) {
    std::optional<Job> job = ledger_.take_next(now);
    if (!job) return;
    const CommandKind kind = job->command.kind;
    ActiveJob next{std::move(*job), first_step(kind)};
    if (needs_initialization(next.job.command)) {
      if (!init_known()) {
        next.check_initialized_first = true;
      } else if (!state_.initialized) {
        if (kind == CommandKind::stop) {
          // Nothing moves before initialization: there is nothing to stop.
          ledger_.complete(next.job, CommandSuccess{state_.position, GraspOutcome::none});
        } else {
          set_error(CommandError::not_initialized,
                    fmt::format("{} before initialization", to_string(kind)));
          ledger_.complete(next.job, fail(CommandError::not_initialized));
        }
        continue;
      }
    }
    ledger_.start(std::move(next));
  }
}

bool HandDriver::at_group_gate() const {
  if (!active() || !active()->job.command.group || active()->group_released ||
      active()->check_initialized_first) {
    return false;
  }
  // The frame that starts the motion (or sets the force): what the group
  // wants to leave together. The steps before it go as they come.
  if (const auto* grasp = std::get_if<GraspStep>(&active()->step))
    return *grasp == GraspStep::close;
  if (const auto* init = std::get_if<InitializeStep>(&active()->step))
    return *init == InitializeStep::start;
  return true;
}

bool HandDriver::pass_group_gate(TimePoint now) {
  GroupRelease& group = *active()->job.command.group;
  if (!active()->group_ready) {
    // next_frame() got here: nothing in flight and the interval clear.
    active()->group_ready = true;
    group.ready(now, context_.wake);
  }
  switch (group.verdict(now)) {
    case GroupRelease::Verdict::hold:
      return false;
    case GroupRelease::Verdict::go:
      // Only in the scheduler's group sweep, so a bus's members go back to back.
      if (!releasing_group_) return false;
      active()->group_released = true;
      return true;
    case GroupRelease::Verdict::abandoned:
      set_error(CommandError::cancelled, "group command abandoned: " + group.abandoned_because());
      ledger_.finish_active(fail(CommandError::cancelled));
      return false;
  }
  return false;
}

bool HandDriver::holding_for_group() const {
  return active() && active()->group_ready && !active()->group_released;
}

Message HandDriver::send_job(Message message, TimePoint now) {
  const bool retryable =
      // CAN ID and baud rate reply only once stored: a re-send would store twice.
      !(message.access == protocol::Access::write && is_admin_register(message.reg));
  if (!std::exchange(active()->frame_sent, true)) {
    context_.latency.command_to_frame.observe(now - active()->job.submitted);
  }
  return slot_.send(message, Purpose::job, now, retryable, reply_timeout_for(active()->job));
}

std::optional<Message> HandDriver::job_frame(TimePoint now) {
  start_next_job(now);
  if (!active()) return std::nullopt;
  const std::uint8_t id = state_.can_id;
  const Command& command = active()->job.command;
  if (active()->check_initialized_first)
    return send_job(protocol::make_read(id, reg::kInitialize), now);
  if (at_group_gate() && !pass_group_gate(now)) return std::nullopt;

  switch (command.kind) {
    case CommandKind::initialize:
      return initialize_frame(now, std::get<InitializeStep>(active()->step));
    case CommandKind::grasp:
      return grasp_frame(now, std::get<GraspStep>(active()->step));
    case CommandKind::stop:
      return stop_frame(now, std::get<StopStep>(active()->step));
    case CommandKind::move_to:
      finger_motion_sent(command.value, command.value == 0);
      return send_job(protocol::make_write(id, reg::kPosition, command.value), now);
    case CommandKind::release:
      finger_motion_sent(command.value, false);
      return send_job(protocol::make_write(id, reg::kPosition, command.value), now);
    case CommandKind::rotate_to:
      rotation_motion_sent(command.value);
      return send_job(protocol::make_write(id, reg::kRotation, command.value), now);
    case CommandKind::set_closing_force:
      return send_job(protocol::make_write(id, reg::kClosingForce, command.value), now);
    case CommandKind::set_opening_force:
      return send_job(protocol::make_write(id, reg::kOpeningForce, command.value), now);
    case CommandKind::read_register:
      return send_job(protocol::make_read(id, command.reg), now);
    case CommandKind::write_register:
      if (command.reg == reg::kPosition) finger_motion_sent(command.value, command.value == 0);
      if (command.reg == reg::kRotation) rotation_motion_sent(command.value);
      return send_job(protocol::make_write(id, command.reg, command.value), now);
  }
  return std::nullopt;
}

std::optional<Message> HandDriver::initialize_frame(TimePoint now, InitializeStep step) {
  // The document's frames: enable the feedback, then initialize (data 0).
  const std::uint8_t id = state_.can_id;
  switch (step) {
    case InitializeStep::enable_feedback:
      return send_job(protocol::make_write(id, reg::kInitFeedback, 0), now);
    case InitializeStep::start:
      return send_job(protocol::make_write(id, reg::kInitialize, 0), now);
  }
  return std::nullopt;
}

std::optional<Message> HandDriver::grasp_frame(TimePoint now, GraspStep step) {
  const std::uint8_t id = state_.can_id;
  switch (step) {
    case GraspStep::set_force:
      return send_job(protocol::make_write(id, reg::kClosingForce, active()->job.command.value),
                      now);
    case GraspStep::close:
      finger_motion_sent(0, true);
      return send_job(protocol::make_write(id, reg::kPosition, 0), now);
  }
  return std::nullopt;
}

std::optional<Message> HandDriver::stop_frame(TimePoint now, StopStep step) {
  // Read where the fingers and the rotation are, and make that their target.
  const std::uint8_t id = state_.can_id;
  switch (step) {
    case StopStep::read_position:
      return send_job(protocol::make_read(id, reg::kPosition), now);
    case StopStep::hold_position:
      finger_motion_sent(active()->held, false);
      return send_job(protocol::make_write(id, reg::kPosition, active()->held), now);
    case StopStep::read_rotation:
      return send_job(protocol::make_read(id, reg::kRotation), now);
    case StopStep::hold_rotation:
      rotation_motion_sent(active()->held);
      return send_job(protocol::make_write(id, reg::kRotation, active()->held), now);
  }
  return std::nullopt;
}

// ---------------------------------------------------------------------------
// Probes and reads of the hand's own state

std::optional<Message> HandDriver::background_frame(TimePoint now) {
  if (Online* on = online()) return online_frame(*on, now);
  auto& offline = std::get<Offline>(link_);
  if (now < offline.next_probe_at) return std::nullopt;
  offline.next_probe_at = now + options_.offline_probe_interval;
  return slot_.send(protocol::make_read(state_.can_id, reg::kFirmwareVersion), Purpose::probe, now,
                    false, options_.reply_timeout);
}

std::optional<Message> HandDriver::online_frame(Online& on, TimePoint now) {
  const std::uint8_t id = state_.can_id;
  if (end_of_motion_.read_due) {
    end_of_motion_.read_due = false;
    return slot_.send(protocol::make_read(id, reg::kPosition), Purpose::confirm_position, now, true,
                      options_.reply_timeout);
  }
  if (end_of_rotation_.read_due) {
    end_of_rotation_.read_due = false;
    return slot_.send(protocol::make_read(id, reg::kRotation), Purpose::confirm_rotation, now, true,
                      options_.reply_timeout);
  }
  Initializing* init = std::get_if<Initializing>(&on.init);
  if (init && (init->check_now || now >= init->next_check_at)) {
    init->check_now = false;
    init->next_check_at = now + options_.poll_interval_moving;
    return slot_.send(protocol::make_read(id, reg::kInitialize), Purpose::init_check, now, false,
                      options_.reply_timeout);
  }
  if (!on.refresh.empty()) {
    const Register r = on.refresh.front();
    on.refresh.pop_front();
    return slot_.send(protocol::make_read(id, r), Purpose::refresh, now, true,
                      options_.reply_timeout);
  }
  PollSchedule& poll = on.poll;
  const std::optional<std::size_t> next =
      next_poll(poll_plan(), poll.last_read, poll.previous, now);
  if (!next) return std::nullopt;
  poll.last_read[*next] = now;
  poll.previous = next;
  return slot_.send(protocol::make_read(id, kPolledRegisters[*next]), Purpose::poll, now, false,
                    options_.reply_timeout);
}

// ---------------------------------------------------------------------------
// Motions started by sending

void HandDriver::finger_motion_sent(std::int32_t target, bool gripping) {
  if (active()) active()->motion_sent = true;
  // A grasp or release waiting for the previous motion to end is superseded.
  ledger_.finish_motion_waiter(fail(CommandError::cancelled));
  ++finger_epoch_;
  finger_motion_ = FingerMotion{target, gripping, state_.position < 0 || target < state_.position};
  hold_untouched_ = false;
  state_.target_position = target;
  state_.grip = GripState::moving;
}

void HandDriver::rotation_motion_sent(std::int32_t target) {
  if (active()) active()->motion_sent = true;
  rotation_motion_ = RotationMotion{target};
  state_.rotation_target = target;
  state_.rotation_state = RotationState::moving;
}

}  // namespace dh3::hand
